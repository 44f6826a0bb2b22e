// `narval info FILE [--json]`: the grids of a .vdb or .vol file as a user frames a camera or picks a
// temperature scale with them. Values derived from how the test files are written
// (tests/vdb_test_file.h, writeVdbTestFile "emission"):
// - "smoke": voxels (0..7)³ = 0.5, voxel size 1, identity transform: index box [0, 7]³, world box
//   [-0.5, 7.5]³ (voxel i covers [i - ½, i + ½]), 8³ = 512 active voxels, 2048 bytes dense;
// - "heat": voxels -1..20 on each axis at voxel size 0.5, translated by (-1, -1, -1): world box
//   0.5·(-1.5) - 1 = -1.75 to 0.5·20.5 - 1 = 9.25, 22³ = 10648 active voxels; values
//   100 + 10x + 20y + 30z at the voxel centres x = y = z from -1.5 (10) to 9 (640);
// - "velocity": one Vec3 voxel (1, 0, 0) at (1, 2, 3): length 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include <nlohmann/json.hpp>

#include <openvdb/openvdb.h>

#include <filesystem>

#include "cli/cli_fixture.h"
#include "vdb_test_file.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

class InfoCli : public test::CliFixture {};

bool hasLine(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

TEST_F(InfoCli, DescribesEveryGridOfAVdb) {
  writeVdbTestFile((dir_ / "fire.vdb").string(), "emission");
  const test::RunResult r = run("info fire.vdb --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json grids = nlohmann::json::parse(r.out);
  ASSERT_EQ(grids.size(), 3u);
  const nlohmann::json& smoke = grids[0];
  EXPECT_EQ(smoke["name"], "smoke");
  EXPECT_EQ(smoke["file"], "fire.vdb");
  EXPECT_EQ(smoke["type"], "float");
  EXPECT_EQ(smoke["class"], "fog volume");
  EXPECT_EQ(smoke["active_voxels"], 512);
  EXPECT_EQ(smoke["index_min"], nlohmann::json({0, 0, 0}));
  EXPECT_EQ(smoke["index_max"], nlohmann::json({7, 7, 7}));
  EXPECT_EQ(smoke["voxel_size"], nlohmann::json({1.0, 1.0, 1.0}));
  EXPECT_EQ(smoke["world_min"], nlohmann::json({-0.5, -0.5, -0.5}));
  EXPECT_EQ(smoke["world_max"], nlohmann::json({7.5, 7.5, 7.5}));
  EXPECT_EQ(smoke["value_min"], 0.5);
  EXPECT_EQ(smoke["value_max"], 0.5);
  EXPECT_EQ(smoke["dense_bytes"], 2048);
  EXPECT_GT(smoke["memory_bytes"].get<double>(), 2048);  // a leaf node (8³ floats) and the tree above it
  const nlohmann::json& heat = grids[1];
  EXPECT_EQ(heat["name"], "heat");
  EXPECT_EQ(heat["active_voxels"], 10648);
  EXPECT_EQ(heat["index_min"], nlohmann::json({-1, -1, -1}));
  EXPECT_EQ(heat["index_max"], nlohmann::json({20, 20, 20}));
  EXPECT_EQ(heat["voxel_size"], nlohmann::json({0.5, 0.5, 0.5}));
  EXPECT_EQ(heat["world_min"], nlohmann::json({-1.75, -1.75, -1.75}));
  EXPECT_EQ(heat["world_max"], nlohmann::json({9.25, 9.25, 9.25}));
  EXPECT_NEAR(heat["value_min"].get<double>(), 10, 1e-4);
  EXPECT_NEAR(heat["value_max"].get<double>(), 640, 1e-4);
  const nlohmann::json& velocity = grids[2];
  EXPECT_EQ(velocity["type"], "vec3s");
  EXPECT_EQ(velocity["active_voxels"], 1);
  EXPECT_EQ(velocity["index_min"], nlohmann::json({1, 2, 3}));
  EXPECT_EQ(velocity["value_max"], 1.0);
  EXPECT_EQ(velocity["dense_bytes"], 0);  // narval does not load vector grids

  const test::RunResult t = run("info fire.vdb");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_TRUE(hasLine(t.out, "fire.vdb: 3 grids")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "  smoke: float, fog volume, 512 active voxels")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "    index box   [0, 0, 0] to [7, 7, 7] (8 x 8 x 8)")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "    world box   [-1.75, -1.75, -1.75] to [9.25, 9.25, 9.25]")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "    voxel size  0.5 x 0.5 x 0.5")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "    values      10 to 640")) << t.out;
  EXPECT_TRUE(hasLine(t.out, "    values      length 1 to 1")) << t.out;
}

TEST_F(InfoCli, DescribesAVolFile) {
  write("t.vol", "2 1 1\n0 3.5\n");
  const test::RunResult r = run("info t.vol");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "t.vol: 1 grid\n"
            "  (unnamed): float, fog volume, 1 active voxels\n"
            "    index box   [0, 0, 0] to [1, 0, 0] (2 x 1 x 1)\n"
            "    voxel size  1 x 1 x 1\n"
            "    world box   [0, 0, 0] to [2, 1, 1]\n"
            "    values      0 to 3.5\n"
            "    memory      8 B, dense in narval 8 B\n");
}

// Every shipped real grid (../shared/data/volumes, or NARVAL_DATA_DIR) against what OpenVDB wrote
// into the file when it saved it, read here without narval's code: the per-grid metadata
// file_voxel_count, file_bbox_min and file_bbox_max, the grid's name, value type and class, and
// the transform's voxel size.
TEST_F(InfoCli, EveryShippedGridAgreesWithOpenVdbsOwnMetadata) {
  const std::filesystem::path folder = std::filesystem::path(test::realDataPath("x")).parent_path();
  std::vector<std::string> files;
  if (std::filesystem::is_directory(folder))
    for (const auto& e : std::filesystem::directory_iterator(folder))
      if (e.path().extension() == ".vdb") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) GTEST_SKIP() << "real data absent: no .vdb in " << folder << " (set NARVAL_DATA_DIR)";
  openvdb::initialize();
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    const test::RunResult r = run("info '" + path + "' --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json grids = nlohmann::json::parse(r.out);
    openvdb::io::File file(path);
    file.open(false);  // no delayed loading: metadata only below
    const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
    file.close();
    ASSERT_EQ(grids.size(), metas->size());
    for (const openvdb::GridBase::Ptr& m : *metas) {
      const openvdb::GridBase& meta = *m;
      SCOPED_TRACE(meta.getName());
      const auto named = std::find_if(grids.begin(), grids.end(),
                                      [&](const nlohmann::json& g) { return g["name"] == meta.getName(); });
      ASSERT_NE(named, grids.end()) << "narval info does not list it";
      const nlohmann::json& g = *named;
      EXPECT_EQ(g["type"], meta.valueType());
      EXPECT_EQ(g["class"], openvdb::GridBase::gridClassToString(meta.getGridClass()));
      const auto count = meta.getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT);
      const auto lo = meta.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
      const auto hi = meta.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
      ASSERT_TRUE(count && lo && hi) << "the file does not carry OpenVDB's statistics metadata";
      EXPECT_EQ(g["active_voxels"].get<int64_t>(), count->value());
      EXPECT_EQ(g["index_min"], nlohmann::json({lo->value().x(), lo->value().y(), lo->value().z()}));
      EXPECT_EQ(g["index_max"], nlohmann::json({hi->value().x(), hi->value().y(), hi->value().z()}));
      const openvdb::Vec3d voxel = meta.transform().voxelSize();
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(g["voxel_size"][a].get<double>(), voxel[a], 1e-9 * voxel[a]);
    }
  }
}

TEST_F(InfoCli, UnreadableFilesAreOneLineAndExitTwo) {
  test::RunResult r = run("info nope.vdb");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: nope.vdb: cannot open the file: no such file\n");
  EXPECT_EQ(r.out, "");
  write("s.json", "{}");
  r = run("info s.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: s.json: unknown volume file type '.json' (narval reads .vdb and .vol)\n");
  write("bad.vdb", "not a vdb file at all");
  r = run("info bad.vdb");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("narval: bad.vdb: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace narval
