// The .obj material reader behind TexturedMesh::load's normal-texture fallback (mesh/mtl_file.hpp),
// tested directly so it is exercised on every assimp, not only on those (< 5.1) that need it.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/mtl_file.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

namespace fs = std::filesystem;
using detail::MtlMaterial;
using detail::parseMtl;

void writeFile(const std::string& path, const std::string& content) {
  std::ofstream file(path, std::ios::binary);
  file << content;
  ASSERT_TRUE(file.good()) << path;
}

TEST(MtlFile, NormBeatsBumpAndOptionsAreSkipped) {
  const std::vector<MtlMaterial> materials = parseMtl(
      "# exported\n"
      "map_Bump stray.png\n"  // before any newmtl: belongs to no material
      "newmtl first\n"
      "Kd 0.8 0.8 0.8\n"
      "map_Bump -bm 1.0 bump.png\n"
      "norm -bm 0.5 -o 0.1 0.2 -s 2 2 2 -clamp on normal.png\n"
      "newmtl second\n"
      "bump -o 0.5 -mm 0 1 b.png\n"
      "newmtl third\n");
  ASSERT_EQ(materials.size(), 3u);
  EXPECT_EQ(materials[0].name, "first");
  EXPECT_EQ(materials[0].norm, "normal.png");
  EXPECT_EQ(materials[0].bump, "bump.png");
  EXPECT_EQ(materials[0].normalTexture(), "normal.png");
  EXPECT_EQ(materials[1].name, "second");
  EXPECT_EQ(materials[1].normalTexture(), "b.png");  // -o with one number, then -mm with two
  EXPECT_EQ(materials[2].name, "third");
  EXPECT_EQ(materials[2].normalTexture(), "");
}

TEST(MtlFile, NamesWithSpacesQuotesCrlfAndKeywordCase) {
  const std::vector<MtlMaterial> materials = parseMtl(
      "newmtl skin tone\r\n"
      "MAP_BUMP -bm 1.0 textures/sphere normal.png  \r\n"
      "newmtl quoted\r\n"
      "Norm \"my maps/n 1.png\" # a comment\r\n"
      "newmtl hash\n"
      "map_Kn tex#2.png\n");
  ASSERT_EQ(materials.size(), 3u);
  EXPECT_EQ(materials[0].name, "skin tone");
  EXPECT_EQ(materials[0].normalTexture(), "textures/sphere normal.png");
  EXPECT_EQ(materials[1].normalTexture(), "my maps/n 1.png");
  EXPECT_EQ(materials[2].normalTexture(), "tex#2.png");
}

TEST(MtlFile, ObjMaterialLibraries) {
  test::ScratchDirectory dir;
  writeFile(dir.path("with space.mtl"), "newmtl m\n");
  EXPECT_EQ(
      detail::parseObjMaterialLibraries("mtllib a.mtl b.mtl\nv 0 0 0\nmtllib c.mtl\n", dir.root()),
      (std::vector<std::string>{"a.mtl", "b.mtl", "c.mtl"}));
  // An unquoted name with a space that exists is one name; a quoted one is always one name.
  EXPECT_EQ(detail::parseObjMaterialLibraries("mtllib with space.mtl\r\n", dir.root()),
            (std::vector<std::string>{"with space.mtl"}));
  EXPECT_EQ(detail::parseObjMaterialLibraries("mtllib \"x y.mtl\" z.mtl\n", dir.root()),
            (std::vector<std::string>{"x y.mtl", "z.mtl"}));
  EXPECT_TRUE(detail::parseObjMaterialLibraries("v 0 0 0\n# mtllib a.mtl\n", dir.root()).empty());
}

TEST(MtlFile, MaterialsOfAnObjComeWithTheirLibrarysDirectory) {
  test::ScratchDirectory dir;
  fs::create_directories(dir.path("materials"));
  writeFile(dir.path("materials/a.mtl"), "newmtl m\nnorm ../textures/n.png\n");
  writeFile(dir.path("b.mtl"), "newmtl m\nnorm other.png\nnewmtl k\nmap_Bump k.png\n");
  writeFile(dir.path("x.obj"), "mtllib missing.mtl materials/a.mtl b.mtl\nv 0 0 0\n");
  const std::vector<detail::ObjMaterial> materials = detail::readObjMaterials(dir.path("x.obj"));
  ASSERT_EQ(materials.size(), 3u);  // the missing library is skipped
  // The first library that defines a name decides.
  const detail::ObjMaterial* m = detail::findObjMaterial(materials, "m");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->material.normalTexture(), "../textures/n.png");
  EXPECT_EQ(fs::path(m->mtl_directory), fs::path(dir.path("materials")).lexically_normal());
  const detail::ObjMaterial* k = detail::findObjMaterial(materials, "k");
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(fs::path(k->mtl_directory), fs::path(dir.root()).lexically_normal());
  EXPECT_EQ(detail::findObjMaterial(materials, "none"), nullptr);
  test::expectError([&] { detail::readObjMaterials(dir.path("absent.obj")); }, {"absent.obj"});
}

// The loader reads the .mtl itself. A library in another directory: the texture's path is
// relative to that .mtl (as OBJ tools resolve it), whether or not assimp reads `norm`.
TEST(MtlFile, LoaderResolvesAgainstTheLibrarysDirectory) {
  test::ScratchDirectory dir;
  fs::create_directories(dir.path("materials"));
  writeFile(dir.path("materials/n.png"), "not read by the loader");
  writeFile(dir.path("materials/a.mtl"), "newmtl m\nnorm -bm 1.0 n.png\n");
  writeFile(dir.path("a.obj"),
            "mtllib materials/a.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
            "vt 0 1\nf 1/1 2/2 3/3\n");
  EXPECT_EQ(fs::path(TexturedMesh::load(dir.path("a.obj")).normalTexturePath()),
            fs::path(dir.path("materials/n.png")).lexically_normal());
}

// Maps that assimp 5.2 does not report (an upper-case keyword, `-o` with one number) or reports
// wrongly (a quoted name keeps its quotes): the loader's own reading is the one used, which is
// the path an assimp without `norm` (< 5.1) takes for every .obj.
TEST(MtlFile, LoaderUsesItsOwnReadingWhereAssimpsDiffers) {
  test::ScratchDirectory dir;
  const std::string obj_body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const struct {
    std::string map_line, texture;
  } cases[] = {{"NORM upper.png", "upper.png"},
               {"norm -o 0.5 offset.png", "offset.png"},
               {"norm \"quoted name.png\"", "quoted name.png"},
               {"map_Bump -bm 1.0 \"sub dir/bump map.png\"", "sub dir/bump map.png"}};
  int index = 0;
  for (const auto& c : cases) {
    const std::string stem = "case" + std::to_string(index++);
    writeFile(dir.path(stem + ".mtl"), "newmtl m\r\n" + c.map_line + "\r\n");
    writeFile(dir.path(stem + ".obj"), "mtllib " + stem + ".mtl\nusemtl m\n" + obj_body);
    const TexturedMesh mesh = TexturedMesh::load(dir.path(stem + ".obj"));
    EXPECT_EQ(fs::path(mesh.normalTexturePath()), fs::path(dir.path(c.texture)).lexically_normal())
        << c.map_line;
  }
  // A missing library or texture is no error while loading: the mesh loads without texture, or
  // with a path that rendering reports as missing (as before).
  writeFile(dir.path("lost.obj"), "mtllib lost.mtl\nusemtl m\n" + obj_body);
  EXPECT_TRUE(TexturedMesh::load(dir.path("lost.obj")).normalTexturePath().empty());
}

}  // namespace
}  // namespace norm2tex
