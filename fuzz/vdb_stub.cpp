// vdb_stub.cpp: vol_io.cpp's loadGrid dispatches .vdb files to loadVdb (vdb_io.cpp, OpenVDB). The
// fuzz targets never call loadGrid; this definition lets them link without OpenVDB.
#include <cstdio>
#include <cstdlib>

#include "volume/dense_grid.h"

namespace narval {

DenseGrid loadVdb(const std::string&, const std::string&) {
  std::fprintf(stderr, "vdb_stub.cpp: loadVdb is not part of the fuzz build\n");
  std::abort();
}

}  // namespace narval
