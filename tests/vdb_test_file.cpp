#include "vdb_test_file.h"

#include <openvdb/openvdb.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace narval {

void writeVdbTestFile(const std::string& path, const std::string& kind) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  openvdb::GridPtrVec grids;
  if (kind == "vec3") {
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
    v->setName("velocity");
    grids.push_back(v);
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    f->setName("heat");
    grids.push_back(f);
  } else if (kind == "emission") {
    // Density "smoke": voxels (0..7)³ = 0.5 at voxel size 1. Emission "heat": voxel size 0.5,
    // translated by (−1, −1, −1), voxels −1..20 on each axis holding 100 + 10x + 20y + 30z of
    // their world centre (x, y, z), a field trilinear filtering reproduces exactly; its box
    // covers the smoke's with a voxel to spare. And a Vec3 grid "velocity".
    openvdb::FloatGrid::Ptr smoke = openvdb::FloatGrid::create(0.0f);
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) smoke->tree().setValue(openvdb::Coord(x, y, z), 0.5f);
    smoke->setName("smoke");
    grids.push_back(smoke);
    openvdb::FloatGrid::Ptr heat = openvdb::FloatGrid::create(0.0f);
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.5);
    xf->postTranslate(openvdb::Vec3d(-1, -1, -1));
    heat->setTransform(xf);
    for (int k = -1; k <= 20; ++k)
      for (int j = -1; j <= 20; ++j)
        for (int i = -1; i <= 20; ++i) {
          const openvdb::Vec3d w = xf->indexToWorld(openvdb::Coord(i, j, k));
          heat->tree().setValue(openvdb::Coord(i, j, k), float(100 + 10 * w.x() + 20 * w.y() + 30 * w.z()));
        }
    heat->setName("heat");
    grids.push_back(heat);
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
    v->setName("velocity");
    grids.push_back(v);
  } else if (kind == "frustum") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(1, 1, 1), 1.0f);
    f->setName("density");
    const openvdb::BBoxd box(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10));
    f->setTransform(openvdb::math::Transform::createFrustumTransform(box, 0.5, 10.0, 1.0));
    grids.push_back(f);
  } else if (kind == "huge") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(-10, -10, -10), 1.0f);
    f->tree().setValue(openvdb::Coord(2037, 2037, 2037), 1.0f);
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "empty") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "no grids") {
    // A valid file holding no grid at all.
  } else if (kind == "invalid") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    f->tree().setValue(openvdb::Coord(1, 0, 0), std::numeric_limits<float>::quiet_NaN());
    f->tree().setValue(openvdb::Coord(2, 0, 0), -1.0f);
    f->tree().setValue(openvdb::Coord(3, 0, 0), std::numeric_limits<float>::infinity());
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "affine") {
    // Voxels (3,4,5)..(4,6,8) with value x + 10y + 100z, under rotate(30 deg about z) * scale(2,3,4)
    // then translate(1,2,3): world = M * ijk + t with M = R * S.
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    for (int z = 5; z <= 8; ++z)
      for (int y = 4; y <= 6; ++y)
        for (int x = 3; x <= 4; ++x) f->tree().setValue(openvdb::Coord(x, y, z), float(x + 10 * y + 100 * z));
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    m.preScale(openvdb::Vec3d(2, 3, 4));
    m.postRotate(openvdb::math::Z_AXIS, M_PI / 6.0);
    m.postTranslate(openvdb::Vec3d(1, 2, 3));
    f->setTransform(openvdb::math::Transform::createLinearTransform(m));
    f->setName("density");
    grids.push_back(f);
  } else {
    throw std::invalid_argument("writeVdbTestFile: unknown kind '" + kind + "'");
  }
  for (auto& g : grids) g->setGridClass(openvdb::GRID_FOG_VOLUME);
  openvdb::io::File out(path);
  out.write(grids);
  out.close();
}

}  // namespace narval
