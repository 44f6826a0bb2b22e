/* emission_kinds.h: the medium's emission kinds, one line each (emission.h evaluates them). The
 * ids, the unknown-kind checks (scene_kinds.h, render/kernel_features.cpp) and whether a kind
 * emits (and so needs kernels built with -DEMISSION) are generated from this list.
 * Columns: id, value, 1 when the kind emits. */
#ifndef NARVAL_EMISSION_KINDS_H
#define NARVAL_EMISSION_KINDS_H

#define EMISSION_KINDS(X)       \
  X(EMISSION_NONE, 0, 0)        \
  X(EMISSION_COLOR, 1, 1)       \
  X(EMISSION_BLACKBODY, 2, 1)

#define EMISSION_KIND_ID(id, value, emits) id = value,
enum emission_kind { EMISSION_KINDS(EMISSION_KIND_ID) };
#undef EMISSION_KIND_ID

/* 1 for a kind of the list that emits, 0 for EMISSION_NONE, -1 for a kind the list does not know. */
#define EMISSION_KIND_EMITS(id, value, emits) case id: return emits;
static inline int emission_emits(int kind) {
  switch (kind) {
    EMISSION_KINDS(EMISSION_KIND_EMITS)
    default: return -1;
  }
}
#undef EMISSION_KIND_EMITS

#endif
