// Writing and reading .vdb files: values, transforms, grid classes, errors.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "exsynth/errors.hpp"
#include "exsynth/vdb_io.hpp"

namespace {

using exsynth::GridTransform;
using exsynth::Volume;

// A unique file per test so parallel ctest runs do not collide.
class VdbIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ("exsynth_vdb_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;
};

GridTransform test_transform() {
  GridTransform xf;
  xf.origin = {0.5, -1.25, 2.0};
  xf.voxel_size = 0.1;
  return xf;
}

// Values that are never zero, so every voxel of a fog grid stays active.
Volume filled(int nx, int ny, int nz, int channels, float scale) {
  Volume v(nx, ny, nz, channels, 0.0f, test_transform());
  for (std::size_t i = 0; i < v.values().size(); ++i) {
    v.values()[i] = scale * (1.0f + float((i * 37) % 101) / 50.0f);
  }
  return v;
}

void expect_same_transform(const GridTransform& a, const GridTransform& b) {
  EXPECT_NEAR(a.voxel_size, b.voxel_size, 1e-6);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.origin[k], b.origin[k], 1e-6) << "axis " << k;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST_F(VdbIo, RoundTripFloatVec3AndMultiChannel) {
  std::map<std::string, Volume> in;
  in["density"] = filled(6, 5, 4, 1, 1.0f);
  in["velocity"] = filled(6, 5, 4, 3, -0.5f);
  in["color"] = filled(6, 5, 4, 2, 2.0f);
  exsynth::write_vdb(file("a.vdb"), in);

  auto out = exsynth::read_vdb(file("a.vdb"));
  ASSERT_EQ(out.size(), 4u);
  ASSERT_TRUE(out.count("density") && out.count("velocity") && out.count("color_0") &&
              out.count("color_1"));

  auto check_channel = [&](const Volume& got, const Volume& src, int src_channel) {
    ASSERT_EQ(got.nx(), src.nx());
    ASSERT_EQ(got.ny(), src.ny());
    ASSERT_EQ(got.nz(), src.nz());
    expect_same_transform(got.transform(), src.transform());
    for (int z = 0; z < src.nz(); ++z)
      for (int y = 0; y < src.ny(); ++y)
        for (int x = 0; x < src.nx(); ++x)
          EXPECT_NEAR(got.at(x, y, z, 0), src.at(x, y, z, src_channel), 1e-6);
  };
  check_channel(out["density"], in["density"], 0);
  check_channel(out["color_0"], in["color"], 0);
  check_channel(out["color_1"], in["color"], 1);

  const Volume& vel = out["velocity"];
  ASSERT_EQ(vel.channels(), 3);
  expect_same_transform(vel.transform(), test_transform());
  ASSERT_EQ(vel.values().size(), in["velocity"].values().size());
  for (std::size_t i = 0; i < vel.values().size(); ++i)
    EXPECT_NEAR(vel.values()[i], in["velocity"].values()[i], 1e-6);
}

TEST_F(VdbIo, ReadsOnlyRequestedGrids) {
  std::map<std::string, Volume> in;
  in["a"] = filled(3, 3, 3, 1, 1.0f);
  in["b"] = filled(3, 3, 3, 1, 2.0f);
  exsynth::write_vdb(file("ab.vdb"), in);
  auto out = exsynth::read_vdb(file("ab.vdb"), {"b"});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out["b"].at(1, 2, 0), in["b"].at(1, 2, 0), 1e-6);
}

TEST_F(VdbIo, FogZerosAreInactiveSoTheBoxShrinksAndTheOriginFollows) {
  Volume v(8, 8, 8, 1, 0.0f, test_transform());
  v.at(2, 3, 4) = 1.0f;
  v.at(5, 3, 6) = 0.5f;
  exsynth::write_vdb(file("fog.vdb"), {{"density", v}});

  openvdb::initialize();
  openvdb::io::File f(file("fog.vdb"));
  f.open();
  auto grid = f.readGrid("density");
  f.close();
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_FOG_VOLUME);
  EXPECT_EQ(grid->activeVoxelCount(), 2u);

  auto out = exsynth::read_vdb(file("fog.vdb"));
  const Volume& d = out["density"];
  ASSERT_EQ(d.nx(), 4);
  ASSERT_EQ(d.ny(), 1);
  ASSERT_EQ(d.nz(), 3);
  GridTransform want = test_transform();
  want.origin = want.index_to_world(2, 3, 4);
  expect_same_transform(d.transform(), want);
  EXPECT_FLOAT_EQ(d.at(0, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(d.at(3, 0, 2), 0.5f);
  EXPECT_FLOAT_EQ(d.at(1, 0, 1), 0.0f);
}

TEST_F(VdbIo, SdfIsWrittenAsALevelSetWithEveryVoxelActive) {
  Volume sdf(6, 6, 6, 1, 0.0f, test_transform());
  for (int z = 0; z < 6; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x)
        sdf.at(x, y, z) = 0.1f * (std::sqrt(float((x - 2.2) * (x - 2.2) + (y - 2.7) * (y - 2.7) +
                                                  (z - 3.1) * (z - 3.1))) - 2.0f);
  float max_abs = 0.0f;
  for (float s : sdf.values()) max_abs = std::max(max_abs, std::fabs(s));
  exsynth::write_vdb(file("sdf.vdb"), {{"sdf", sdf}});

  openvdb::initialize();
  openvdb::io::File f(file("sdf.vdb"));
  f.open();
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("sdf"));
  f.close();
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_FLOAT_EQ(grid->background(), max_abs);
  EXPECT_EQ(grid->activeVoxelCount(), 216u);
  // Index space and world placement agree with OpenVDB's own view.
  auto acc = grid->getConstAccessor();
  for (int z = 0; z < 6; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x) ASSERT_EQ(acc.getValue(openvdb::Coord(x, y, z)), sdf.at(x, y, z));
  const openvdb::Vec3d w = grid->transform().indexToWorld(openvdb::Coord(1, 2, 3));
  const auto want = test_transform().index_to_world(1, 2, 3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(w[k], want[k], 1e-9);

  auto out = exsynth::read_vdb(file("sdf.vdb"), {"sdf"});
  ASSERT_EQ(out["sdf"].values().size(), sdf.values().size());
  for (std::size_t i = 0; i < sdf.values().size(); ++i)
    EXPECT_NEAR(out["sdf"].values()[i], sdf.values()[i], 1e-6);
  expect_same_transform(out["sdf"].transform(), test_transform());
}

TEST_F(VdbIo, MissingFileIsNamed) {
  const std::string path = file("nope.vdb");
  try {
    exsynth::read_vdb(path);
    FAIL() << "expected IoError";
  } catch (const exsynth::IoError& e) {
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
    EXPECT_TRUE(contains(e.what(), "not found")) << e.what();
  }
}

TEST_F(VdbIo, VoxelsTooSmallForOpenVdbAreRefusedByName) {
  Volume v = filled(2, 2, 2, 1, 1.0f);
  GridTransform t;
  t.voxel_size = 1e-8;
  v.set_transform(t);
  try {
    exsynth::write_vdb(file("tiny.vdb"), {{"density", v}});
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "voxel size 1e-08 is too small")) << e.what();
    EXPECT_TRUE(contains(e.what(), "scale the model up")) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(file("tiny.vdb")));
}

TEST_F(VdbIo, UnwritablePathIsAnIoError) {
  // A folder cannot be written as a file: an I/O error (OSError in Python), not bad input.
  EXPECT_THROW(exsynth::write_vdb(dir_.string(), {{"density", filled(2, 2, 2, 1, 1.0f)}}), exsynth::IoError);
}

TEST_F(VdbIo, MissingGridIsNamedWithTheGridsPresent) {
  exsynth::write_vdb(file("g.vdb"), {{"density", filled(2, 2, 2, 1, 1.0f)}});
  try {
    exsynth::read_vdb(file("g.vdb"), {"temperature"});
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "'temperature'")) << e.what();
    EXPECT_TRUE(contains(e.what(), "'density'")) << e.what();
  }
}

TEST_F(VdbIo, UnsupportedGridTypeIsRejected) {
  openvdb::initialize();
  auto grid = openvdb::Int32Grid::create(0);
  grid->tree().setValue(openvdb::Coord(1, 2, 3), 7);
  grid->setName("labels");
  openvdb::io::File f(file("int.vdb"));
  f.write(openvdb::GridPtrVec{grid});
  f.close();
  try {
    exsynth::read_vdb(file("int.vdb"), {"labels"});
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "labels")) << e.what();
  }
  // Asking for everything skips unsupported grids; here nothing is left.
  EXPECT_THROW(exsynth::read_vdb(file("int.vdb")), exsynth::InvalidInput);
}

TEST_F(VdbIo, TransformsThatDoNotFitOneBoxAreRejected) {
  openvdb::initialize();
  auto make = [](const std::string& name, openvdb::math::Transform::Ptr xf) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    g->setName(name);
    g->setTransform(xf);
    return g;
  };
  auto stretched = openvdb::math::Transform::createLinearTransform(0.1);
  stretched->postScale(openvdb::Vec3d(1.0, 2.0, 1.0));
  openvdb::io::File f(file("stretched.vdb"));
  f.write(openvdb::GridPtrVec{make("d", stretched)});
  f.close();
  try {
    exsynth::read_vdb(file("stretched.vdb"));
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "non-uniform voxel")) << e.what();
  }

  openvdb::io::File g(file("mixed.vdb"));
  g.write(openvdb::GridPtrVec{make("a", openvdb::math::Transform::createLinearTransform(0.1)),
                              make("b", openvdb::math::Transform::createLinearTransform(0.2))});
  g.close();
  EXPECT_THROW(exsynth::read_vdb(file("mixed.vdb")), exsynth::InvalidInput);
  EXPECT_EQ(exsynth::read_vdb(file("mixed.vdb"), {"b"}).at("b").transform().voxel_size, 0.2);
}

TEST_F(VdbIo, NonVdbFileIsAnIoError) {
  {
    std::FILE* fp = std::fopen(file("junk.vdb").c_str(), "w");
    ASSERT_TRUE(fp);
    std::fputs("not a vdb file", fp);
    std::fclose(fp);
  }
  EXPECT_THROW(exsynth::read_vdb(file("junk.vdb")), exsynth::IoError);
}

TEST_F(VdbIo, WriteRejectsBadInput) {
  EXPECT_THROW(exsynth::write_vdb(file("e.vdb"), {}), exsynth::InvalidInput);
  EXPECT_THROW(exsynth::write_vdb(file("e.vdb"), {{"density", Volume()}}), exsynth::InvalidInput);
  EXPECT_THROW(exsynth::write_vdb(file("no_such_dir/e.vdb"), {{"d", filled(2, 2, 2, 1, 1.0f)}}),
               exsynth::IoError);  // a missing folder: an I/O error
  // "c" (2 channels) becomes c_0, c_1 and would clash with "c_0".
  EXPECT_THROW(exsynth::write_vdb(file("e.vdb"),
                                  {{"c", filled(2, 2, 2, 2, 1.0f)}, {"c_0", filled(2, 2, 2, 1, 1.0f)}}),
               exsynth::InvalidInput);
}

}  // namespace
