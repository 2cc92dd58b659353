// OBJ files as artists export them: `usemtl` names per face, mapped to the
// scene's materials by name (one shape per OBJ material), and smoothing
// groups (`s`) made into vertex normals when the file has no `vn`.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/mesh.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"
#include "wavefront/wavefront_tracer.h"

#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
constexpr std::uint16_t kNone = TriangleMesh::kNoFileMaterial;

class ObjMaterials : public test::TempDirTest {
 protected:
  // A scene with materials white, red, wood and lamp, an environment light,
  // and `shapes` (and `extra` top-level keys).
  Scene scene(const std::string& shapes, const std::string& extra = "") const {
    const std::string text = R"({"pathlab_scene": 1, "camera": {"position": [3, 4, 5], "look_at": [0, 0, 0]},
      "film": {"resolution": [12, 12]}, "render": {"spp": 2},
      "materials": {"white": {"type": "diffuse", "albedo": 0.5}, "red": {"type": "diffuse", "albedo": [0.8, 0.1, 0.1]},
                    "wood": {"type": "diffuse", "albedo": [0.5, 0.3, 0.1]}, "lamp": {"type": "emissive", "radiance": 1}},
      "lights": [{"type": "environment", "radiance": 1}],
      "shapes": [)" + shapes + "]" + (extra.empty() ? "" : ", " + extra) + "}";
    return parse_scene(text, dir_ / "s.json");
  }
  // The message of the InputError that loading `shapes` throws.
  std::string error(const std::string& shapes) const {
    try {
      (void)scene(shapes);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no error for " << shapes;
    return "";
  }
};

// Faces before the first `usemtl`, a quad (two triangles) and a triangle in
// "wood", one in "steel", one more in "wood": 5 triangles.
const char* const kFourParts =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
    "f 1 2 3\n"
    "usemtl wood\nf 1 2 3 4\nf 2 5 6\n"
    "usemtl steel\nf 2 6 3\n"
    "usemtl wood\nf 1 5 6\n";

TEST_F(ObjMaterials, FaceMaterialsByNameInTheOrderOfFirstUse) {
  for (const std::string library : {"", "mtllib parts.mtl\n"}) {  // with or without a library line
    MeshLoadReport report;
    const TriangleMesh m = load_mesh(write("parts.obj", library + kFourParts), &report);
    ASSERT_EQ(m.triangles.size(), 6u);
    EXPECT_EQ(m.material_names, (std::vector<std::string>{"wood", "steel"}));
    EXPECT_EQ(m.face_material, (std::vector<std::uint16_t>{kNone, 0, 0, 0, 1, 0}));
    // The library is not read; only with one is there something to say.
    EXPECT_EQ(report.ignored.size(), library.empty() ? 0u : 1u);
  }
}

TEST_F(ObjMaterials, NothingStoredWithoutUsemtl) {
  const TriangleMesh m = load_mesh(write("plain.obj", "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_TRUE(m.face_material.empty());
  EXPECT_TRUE(m.material_names.empty());
}

// tinyobj reads "usemtl" without a blank and stops a name at a blank; an
// empty name is no material. A degenerate face drops its triangle and its
// material with it.
TEST_F(ObjMaterials, NamesAsTinyobjReadsThem) {
  const TriangleMesh m = load_mesh(write("names.obj",
                                         "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 0\n"
                                         "usemtl  a b\nf 1 2 3\n"
                                         "usemtlc\nf 1 2 2\nf 1 2 3\n"
                                         "usemtl\nf 1 2 3\n"));
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"a", "c"}));
  EXPECT_EQ(m.face_material, (std::vector<std::uint16_t>{0, 1, kNone}));
}

// The loader puts a line in front of a file with `usemtl` for tinyobj;
// messages about the file still name the file's own line.
TEST_F(ObjMaterials, TinyobjMessagesKeepTheFileLineNumbers) {
  try {
    (void)load_mesh(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 0 1 2\n"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("zero.obj:5:"), std::string::npos) << e.what();
  }
}

TEST_F(ObjMaterials, SplitKeepsOnlyEachPartsVertices) {
  TriangleMesh m = load_mesh(write("parts.obj", kFourParts));
  m.normals = smooth_vertex_normals(m);
  const auto parts = split_by_face_material(m);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].first, kNone);
  EXPECT_EQ(parts[1].first, 0);
  EXPECT_EQ(parts[2].first, 1);
  EXPECT_EQ(parts[0].second.triangles.size(), 1u);
  EXPECT_EQ(parts[1].second.triangles.size(), 4u);
  EXPECT_EQ(parts[2].second.triangles.size(), 1u);
  EXPECT_EQ(parts[0].second.positions.size(), 3u);
  EXPECT_EQ(parts[1].second.positions.size(), 6u);
  EXPECT_EQ(parts[2].second.positions.size(), 3u);
  for (const auto& [slot, part] : parts) {
    EXPECT_TRUE(part.face_material.empty());
    EXPECT_EQ(part.normals.size(), part.positions.size());
  }
  // The steel triangle is f 2 6 3, in its own numbering.
  const TriangleMesh& steel = parts[2].second;
  EXPECT_EQ(steel.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(steel.positions[1], vec3(2, 1, 0));
  // One part: the mesh as it is.
  const TriangleMesh whole = load_mesh(write("one.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n"));
  const auto one = split_by_face_material(whole);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].first, 0);
  EXPECT_EQ(one[0].second.positions, whole.positions);
}

// ------------------------------------------------------------ the scene

// "materials" maps first, then a scene material of the same name, then
// "material" (also for the faces before the first `usemtl`).
TEST_F(ObjMaterials, PrecedenceMapThenSameNameThenMaterial) {
  write("parts.obj", kFourParts);
  const auto index = [](const Scene& s, const std::string& name) {
    for (std::uint32_t i = 0; i < s.materials.size(); ++i)
      if (s.materials[i].name == name) return i;
    return 999u;
  };
  {
    // wood by its name, steel and the first face by "material".
    const Scene s = scene(R"({"type": "mesh", "file": "parts.obj", "material": "white"})");
    ASSERT_EQ(s.shapes.size(), 3u);
    EXPECT_EQ(s.shapes[0].material, index(s, "white"));
    EXPECT_EQ(s.shapes[1].material, index(s, "wood"));
    EXPECT_EQ(s.shapes[2].material, index(s, "white"));
    EXPECT_EQ(s.shapes[0].mesh.triangles.size(), 1u);
    EXPECT_EQ(s.shapes[1].mesh.triangles.size(), 4u);
    EXPECT_EQ(s.shapes[2].mesh.triangles.size(), 1u);
    EXPECT_EQ(s.shapes[0].description, "shapes[0] (mesh parts.obj, faces before 'usemtl')");
    EXPECT_EQ(s.shapes[1].description, "shapes[0] (mesh parts.obj, material 'wood')");
    EXPECT_EQ(s.shapes[2].description, "shapes[0] (mesh parts.obj, material 'steel')");
  }
  {
    // The map beats the same name.
    const Scene s = scene(R"({"type": "mesh", "file": "parts.obj", "material": "white",
                              "materials": {"wood": "red", "steel": "lamp"}})");
    ASSERT_EQ(s.shapes.size(), 3u);
    EXPECT_EQ(s.shapes[1].material, index(s, "red"));
    EXPECT_EQ(s.shapes[2].material, index(s, "lamp"));
  }
  // Every part matched or mapped: no "material" needed; the transform and
  // flip_normals apply to every part.
  write("named.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl wood\nf 1 2 3\nusemtl steel\nf 1 3 4\n");
  const Scene s = scene(R"({"type": "mesh", "file": "named.obj", "materials": {"steel": "red"},
                            "transform": {"translate": [0, 0, 2]}, "flip_normals": true})");
  ASSERT_EQ(s.shapes.size(), 2u);
  EXPECT_EQ(s.shapes[0].material, index(s, "wood"));
  EXPECT_EQ(s.shapes[1].material, index(s, "red"));
  for (const Shape& shape : s.shapes) {
    EXPECT_TRUE(shape.flip_normals);
    for (const vec3& p : shape.mesh.positions) EXPECT_EQ(p.z, 2.0f);
  }
  // A shape after the mesh's parts is numbered by its entry.
  const Scene two = scene(R"({"type": "mesh", "file": "named.obj", "material": "white"},
                             {"type": "sphere", "material": "white"})");
  ASSERT_EQ(two.shapes.size(), 3u);
  EXPECT_EQ(two.shapes[2].description, "shapes[1] (sphere)");
}

TEST_F(ObjMaterials, AGroupEntryYieldsOneShapePerMaterial) {
  write("parts.obj", kFourParts);
  const Scene s = scene(R"({"type": "sphere", "material": "white", "radius": 0.1})",
                        R"("groups": {"g": [{"type": "mesh", "file": "parts.obj", "material": "white"}]},
                           "instances": [{"group": "g", "transforms": [{"translate": [1, 0, 0]}, {"translate": [-1, 0, 0]}]}])");
  ASSERT_EQ(s.groups.size(), 1u);
  ASSERT_EQ(s.groups[0].shapes.size(), 3u);
  for (const std::uint32_t id : s.groups[0].shapes) EXPECT_TRUE(s.shapes[id].in_group);
  EXPECT_EQ(s.shapes[s.groups[0].shapes[1]].description, "groups/g[0] (mesh parts.obj, material 'wood')");
}

TEST_F(ObjMaterials, UnmatchedNamesWithoutMaterialAreAnError) {
  write("parts.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl woood\nf 1 2 3\nusemtl steel\nf 1 3 2\n");
  const std::string e = error(R"({"type": "mesh", "file": "parts.obj"})");
  EXPECT_NE(e.find("/shapes/0: missing required key 'material': parts.obj uses materials that no scene material "
                   "matches: 'woood' (did you mean 'wood'?), 'steel'; give 'material' for them, or map OBJ names to "
                   "scene materials in 'materials'"),
            std::string::npos)
      << e;
  write("before.obj", kFourParts);
  const std::string b = error(R"({"type": "mesh", "file": "before.obj", "materials": {"steel": "red"}})");
  EXPECT_NE(b.find("missing required key 'material': before.obj has faces before its first 'usemtl'; give"),
            std::string::npos)
      << b;
  // A file without `usemtl` needs "material" as before.
  write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(error(R"({"type": "mesh", "file": "plain.obj"})").find("/shapes/0: missing required key 'material'"),
            std::string::npos);
}

TEST_F(ObjMaterials, UnknownNamesInMaterialsAreAnError) {
  write("parts.obj", kFourParts);
  const std::string e = error(R"({"type": "mesh", "file": "parts.obj", "material": "white", "materials": {"stel": "red"}})");
  EXPECT_NE(e.find("/shapes/0/materials/stel: parts.obj has no material named 'stel' (did you mean 'steel'?)"),
            std::string::npos)
      << e;
  write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string p = error(R"({"type": "mesh", "file": "plain.obj", "material": "white", "materials": {"a": "red"}})");
  EXPECT_NE(p.find("/shapes/0/materials/a: plain.obj has no material named 'a' (it has no 'usemtl')"), std::string::npos)
      << p;
  // The value must name a scene material.
  const std::string v = error(R"({"type": "mesh", "file": "parts.obj", "material": "white", "materials": {"steel": "redd"}})");
  EXPECT_NE(v.find("/shapes/0/materials/steel: no material named 'redd' (did you mean 'red'?)"), std::string::npos) << v;
  // Only a mesh takes "materials".
  EXPECT_NE(error(R"({"type": "box", "material": "white", "materials": {}})").find("unknown key 'materials'"),
            std::string::npos);
}

// ------------------------------------------------------------ smoothing groups

// A cube of 8 positions and 6 quads, counter-clockwise seen from outside;
// `groups[f]` is face f's `s` line ("" for none).
std::string cube(const std::vector<std::string>& groups) {
  const char* const faces[6] = {"5 6 7 8", "1 4 3 2", "2 3 7 6", "1 5 8 4", "4 8 7 3", "1 2 6 5"};
  std::string text = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";
  for (int f = 0; f < 6; ++f) text += (groups[f].empty() ? "" : "s " + groups[f] + "\n") + "f " + faces[f] + "\n";
  return text;
}
const vec3 kFaceNormals[6] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};

TEST_F(ObjMaterials, SixGroupsGiveFaceNormals) {
  const TriangleMesh m = load_mesh(write("six.obj", cube({"1", "2", "3", "4", "5", "6"})));
  ASSERT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.positions.size(), 24u);  // every corner split between its three groups
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (std::size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.normals[m.triangles[t][k]], kFaceNormals[t / 2]) << t;
}

TEST_F(ObjMaterials, OneGroupGivesDiagonalNormals) {
  const TriangleMesh m = load_mesh(write("one.obj", cube({"1", "1", "1", "1", "1", "1"})));
  EXPECT_EQ(m.positions.size(), 8u);
  ASSERT_EQ(m.normals.size(), 8u);
  for (std::size_t v = 0; v < 8; ++v) {
    const vec3 diagonal = glm::normalize(m.positions[v]);
    EXPECT_NEAR(glm::dot(m.normals[v], diagonal), 1.0f, 1e-6f) << v;
  }
  // As "smooth" computes it for the whole mesh.
  const std::vector<vec3> smooth = smooth_vertex_normals(m);
  for (std::size_t v = 0; v < 8; ++v) EXPECT_EQ(m.normals[v], smooth[v]);
}

// Top face `s off`, the rest in group 1, the bottom face in group 2: the top
// is flat; the sides share normals with each other, not with the bottom.
TEST_F(ObjMaterials, MixedGroupsSplitWhereGroupsMeet) {
  const TriangleMesh m = load_mesh(write("mix.obj", cube({"1", "1", "1", "1", "off", "2"})));
  // 8 for group 1 (4 side faces touch all 8 corners), 4 flat top corners, 4 bottom corners.
  EXPECT_EQ(m.positions.size(), 16u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (std::size_t t = 0; t < 12; ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.triangles[t][k];
      const vec3 n = m.normals[v];
      if (t / 2 == 4) {
        EXPECT_EQ(n, vec3(0, 1, 0)) << t;  // flat top
      } else if (t / 2 == 5) {
        EXPECT_EQ(n, vec3(0, -1, 0)) << t;  // the bottom's own group: flat, as it is planar
      } else {
        // Side corners: the sides' (and +z/-z's) normals, level with the top and bottom.
        EXPECT_EQ(n.y, 0.0f) << t;
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
        EXPECT_NEAR(std::abs(n.x), std::sqrt(0.5f), 1e-6f) << t;
      }
    }
  }
}

// Normals from the file win; "flat" and "smooth" ignore the groups.
TEST_F(ObjMaterials, FileNormalsAndTheNormalsKeyOverrideTheGroups) {
  // A fold in one group, whose file normals all point up.
  const TriangleMesh with_vn = load_mesh(
      write("vn.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nvn 0 0 1\ns 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"));
  EXPECT_EQ(with_vn.positions.size(), 4u);
  for (const vec3& n : with_vn.normals) EXPECT_EQ(n, vec3(0, 0, 1));
  write("six.obj", cube({"1", "2", "3", "4", "5", "6"}));
  const auto with = [&](const std::string& normals) {
    return scene(R"({"type": "mesh", "file": "six.obj", "material": "white", "normals": ")" + normals + "\"}");
  };
  EXPECT_EQ(with("file").shapes[0].mesh.normals.size(), 24u);
  const Scene flat = with("flat");
  EXPECT_TRUE(flat.shapes[0].mesh.normals.empty());
  EXPECT_EQ(flat.shapes[0].mesh.positions.size(), 8u);
  const Scene smooth = with("smooth");
  ASSERT_EQ(smooth.shapes[0].mesh.positions.size(), 8u);  // not split by group: smooth over the whole cube
  for (const vec3& n : smooth.shapes[0].mesh.normals) EXPECT_NEAR(std::abs(n.x), std::sqrt(1.0f / 3.0f), 1e-6f);
  MeshLoadOptions off;
  off.smoothing_groups = false;
  EXPECT_TRUE(load_mesh(dir_ / "six.obj", nullptr, off).normals.empty());
}

// Renders `shapes` with both tracers; one FilmSample per pixel sample.
std::vector<std::vector<FilmSample>> render_both(Scene scene) {
  const RenderSettings settings = scene.render;
  const std::size_t n = static_cast<std::size_t>(scene.film.width * scene.film.height * settings.spp);
  const CompiledScene compiled(std::move(scene));
  std::vector<std::vector<FilmSample>> out(2, std::vector<FilmSample>(n));
  ReferenceTracer(compiled, settings).render_batch(0, settings.spp, out[0]);
  WavefrontTracer(compiled, settings, 97, {}, WavefrontStages::Scalar).render_batch(0, settings.spp, out[1]);
  return out;
}

std::size_t differing(const std::vector<std::vector<FilmSample>>& a, const std::vector<std::vector<FilmSample>>& b) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < a.size(); ++t)
    for (std::size_t i = 0; i < a[t].size(); ++i) n += std::memcmp(&a[t][i].L, &b[t][i].L, sizeof(Spectrum)) != 0;
  return n;
}

// Six groups render exactly the flat cube's bits (both tracers); one group
// renders a smooth cube, which differs.
TEST_F(ObjMaterials, SixGroupsRenderTheFlatCubesBits) {
  write("flat.obj", cube({"", "", "", "", "", ""}));
  write("six.obj", cube({"1", "2", "3", "4", "5", "6"}));
  write("one.obj", cube({"1", "1", "1", "1", "1", "1"}));
  const auto render = [&](const std::string& file) {
    return render_both(scene(R"({"type": "mesh", "file": ")" + file + R"(", "material": "white"})"));
  };
  const auto flat = render("flat.obj");
  EXPECT_EQ(differing(flat, render("six.obj")), 0u);
  EXPECT_GT(differing(flat, render("one.obj")), 20u);
}

}  // namespace
}  // namespace pathlab
