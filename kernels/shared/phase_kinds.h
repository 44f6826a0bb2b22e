/* phase_kinds.h: the phase functions, one line each. The ids, the scene loader's names and
 * parameter keys, the unknown-kind checks (scene_kinds.h, render/kernel_features.cpp), the
 * specialisation flag (-DPHASE_FIXED=id) and the dispatch in phase.h are all generated from this
 * list; each kind's mathematics lives in its own header, phase_<prefix>.h, included by phase.h.
 * Columns: id, value, the loader's name, header prefix, the kind's one parameter key in a volume
 * material (0: none), its closed range [lo, hi] and its default. */
#ifndef NARVAL_PHASE_KINDS_H
#define NARVAL_PHASE_KINDS_H

#define PHASE_KINDS(X)                                            \
  X(PHASE_ISOTROPIC, 0, "isotropic", isotropic, 0, 0.0f, 0.0f, 0.0f) \
  X(PHASE_HG, 1, "hg", hg, "g", -1.0f, 1.0f, 0.0f)                 \
  X(PHASE_MIE, 2, "mie", mie, "dropletDiameter", 0.1f, 50.0f, 20.0f)

#define PHASE_KIND_ID(id, value, name, prefix, key, lo, hi, fallback) id = value,
enum phase_kind { PHASE_KINDS(PHASE_KIND_ID) };
#undef PHASE_KIND_ID

/* 1 for a kind of the list: the kernels' entry check (scene_kinds.h) and the host's. */
#define PHASE_KIND_KNOWN(id, value, name, prefix, key, lo, hi, fallback) case id:
static inline int phase_known(int kind) {
  switch (kind) {
    PHASE_KINDS(PHASE_KIND_KNOWN) return 1;
    default: return 0;
  }
}
#undef PHASE_KIND_KNOWN

#endif
