// vdb_test_file.h: .vdb files made for the tests, compiled once (vdb_test_file.cpp) so that test
// sources need not include OpenVDB.
#pragma once

#include <string>

namespace narval {

// Writes a small .vdb that exercises one loader path. kind: "vec3" (Vec3SGrid "velocity" + FloatGrid "heat"), "frustum"
// (FloatGrid "density" under a frustum map), "huge" (two active voxels 2047 apart: a 2048^3 box,
// 32 GiB as dense floats),
// "empty" (FloatGrid "density" without active voxels), "no grids" (a valid file with none), "invalid" (FloatGrid "density", active
// (0..3, 0, 0) = 1, NaN, -1, +inf), "affine" (voxels (3,4,5)..(4,6,8) holding
// x + 10y + 100z, transform translate(1,2,3) * rotateZ(30 deg) * scale(2,3,4)), "emission" (FloatGrid
// "smoke" (0..7)³ = 0.5; FloatGrid "heat" at voxel size 0.5 translated by (-1,-1,-1), voxels
// -1..20 holding 100 + 10x + 20y + 30z of their world centre; Vec3SGrid "velocity").
void writeVdbTestFile(const std::string& path, const std::string& kind);

}  // namespace narval
