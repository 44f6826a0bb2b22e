/* grid_storage_kinds.h: how a density grid may live on the device (grid.h), one line each. The scene
 * loader's names (renderer.storage, --storage), the host's GridStorage values and the build flag
 * that selects each in grid.h are generated from this list; `auto` is the host's choice among them
 * (render/device_grid.h). Columns: the loader's name, the host's enumerator, the -D flag ("": the
 * 3D image, grid.h's default). */
#ifndef NARVAL_GRID_STORAGE_KINDS_H
#define NARVAL_GRID_STORAGE_KINDS_H

#define GRID_STORAGE_KINDS(X)                    \
  X("image", Image, "")                          \
  X("buffer", Buffer, "-DGRID_STORAGE_BUFFER")   \
  X("bricks", Bricks, "-DGRID_STORAGE_BRICKS")

#endif
