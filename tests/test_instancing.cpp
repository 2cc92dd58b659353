// Instancing (Scene::groups placed by Scene::instances): a group's hits are
// resolved in world space - the point within its error bound of the exact
// point at the same barycentrics, the normals perpendicular to the placed
// surface and on its placed front, the shading normal the exact one's
// inverse-transpose image - for a rotation, a mirror with a non-uniform scale
// and a shear; the instanced scene renders what the same shapes flattened
// into world space render; both tracers give the same bits for any thread
// count; the scene file's "groups" and "instances"; a group's triangles are
// stored once.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/film.h"
#include "core/geometry.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/sampling.h"
#include "core/scene_loader.h"
#include "debugtools/path_compare.h"
#include "debugtools/path_recorder.h"
#include "reference/reference_tracer.h"
#include "tests/test_scenes.h"
#include "wavefront/vector_stages.h"
#include "wavefront/wavefront_tracer.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>

namespace pathlab {
namespace {

glm::dmat4 dmat(const mat4& m) { return glm::dmat4(m); }
dvec3 place(const mat4& m, const vec3& p) { return dvec3(dmat(m) * glm::dvec4(dvec3(p), 1.0)); }

// Rays from points around each placement towards its middle, so that most
// of them hit that instance's ball or bead.
TEST(Instancing, ResolvedHitsArePlacedExactly) {
  const CompiledScene compiled(test::cornell_with_instances());
  const Scene& scene = compiled.scene();
  const Shape& ball = scene.shapes[scene.groups[0].shapes[0]];
  const Shape& bead = scene.shapes[scene.groups[0].shapes[1]];
  int ball_hits = 0, bead_hits = 0;
  for (std::uint32_t k = 0; k < scene.instances.size(); ++k) {
    const mat4& m = scene.instances[k].to_world;
    const glm::dmat3 to_normal = glm::transpose(glm::inverse(glm::dmat3(dmat(m))));
    for (int i = 0; i < 400; ++i) {
      const vec2 u((static_cast<float>(i) + 0.5f) / 400.0f, std::fmod(0.618034f * static_cast<float>(i), 1.0f));
      const vec3 target = vec3(place(m, i % 4 == 0 ? bead.center : vec3(0.0f)));
      const vec3 origin = target + 0.8f * square_to_uniform_sphere(u);
      const Ray ray{origin, glm::normalize(target - origin), kInfinity};
      Surfel s;
      if (!compiled.intersect(ray, &s)) continue;
      if (s.instance != k) continue;
      ASSERT_TRUE(scene.shapes[s.shape].in_group);
      ASSERT_NEAR(glm::length(s.n), 1.0f, 1e-5f);
      ASSERT_NEAR(glm::length(s.frame.n), 1.0f, 1e-5f);
      if (s.shape == scene.groups[0].shapes[0]) {
        ++ball_hits;
        // The exact point at the hit's barycentrics (the UV sphere has no
        // texture coordinates, so Surfel::uv holds them), placed in double.
        const glm::uvec3 t = ball.mesh.triangles[s.prim];
        const dvec3 v0 = place(m, ball.mesh.positions[t.x]), v1 = place(m, ball.mesh.positions[t.y]),
                    v2 = place(m, ball.mesh.positions[t.z]);
        const dvec3 exact = (1.0 - s.uv.x - s.uv.y) * v0 + double(s.uv.x) * v1 + double(s.uv.y) * v2;
        for (int c = 0; c < 3; ++c)
          ASSERT_LE(std::abs(double(s.p[c]) - exact[c]), double(s.p_error[c])) << "instance " << k << " axis " << c;
        // Perpendicular to the placed triangle, and outwards: the front of a
        // closed surface stays its outside under a mirror.
        for (const dvec3& e : {v1 - v0, v2 - v0})
          ASSERT_LE(std::abs(glm::dot(dvec3(s.n), e)), 1e-5 * glm::length(e)) << "instance " << k;
        ASSERT_GT(glm::dot(dvec3(s.n), dvec3(s.p) - place(m, vec3(0.0f))), 0.0) << "instance " << k;
        // The shading normal: the exact sphere normal at the point (its
        // direction from the centre in the group's space), through the
        // inverse transpose. Interpolating the vertex normals of 16 rings
        // stays within 0.5 degrees of it.
        const dvec3 local = glm::inverse(glm::dmat3(dmat(m))) * (dvec3(s.p) - place(m, vec3(0.0f)));
        const dvec3 smooth = glm::normalize(to_normal * glm::normalize(local));
        ASSERT_GT(glm::dot(dvec3(s.frame.n), smooth), std::cos(0.5 * 3.141592653589793 / 180.0)) << "instance " << k;
      } else {
        ++bead_hits;
        // On the placed true sphere (an ellipsoid), its normal the sphere's
        // through the inverse transpose.
        const dvec3 local = glm::dvec3(glm::inverse(dmat(m)) * glm::dvec4(dvec3(s.p), 1.0)) - dvec3(bead.center);
        ASSERT_NEAR(glm::length(local), bead.radius, 1e-5 * bead.radius) << "instance " << k;
        ASSERT_GT(glm::dot(dvec3(s.n), glm::normalize(to_normal * local)), 1.0 - 1e-6) << "instance " << k;
        // Where the ray met it: its o + t d, taken into the group's space and
        // reprojected there, so on the ray's line.
        const dvec3 off = dvec3(s.p) - dvec3(ray.origin), dir(ray.dir);
        ASSERT_LT(glm::length(off - glm::dot(off, dir) * dir), 1e-5) << "instance " << k;
        ASSERT_FALSE(s.shading_normal);
      }
    }
  }
  EXPECT_GT(ball_hits, 400);
  EXPECT_GT(bead_hits, 100);
}

// The Cornell box with the UV ball placed by instance_placements(), as a
// group or flattened into world-space copies by transform_mesh, the path
// the file's shapes take, and a true sphere placed or in world space.
Scene cornell_with_balls(bool instanced) {
  Scene scene = builtin_cornell_box();
  scene.film.width = scene.film.height = 24;
  scene.render.spp = 8;
  Shape ball;
  ball.material = scene.shapes.front().material;
  ball.mesh = test::uv_sphere(vec3(0.0f), 1.0f, 16);
  if (instanced) {
    ball.in_group = true;
    scene.groups.push_back({"ball", {static_cast<std::uint32_t>(scene.shapes.size())}});
    scene.shapes.push_back(ball);
    for (const mat4& m : test::instance_placements()) scene.instances.push_back({0, m, "ball"});
  } else {
    for (const mat4& m : test::instance_placements()) {
      Shape copy = ball;
      EXPECT_EQ(transform_mesh(&copy.mesh, m), 0u);
      scene.shapes.push_back(std::move(copy));
    }
  }
  // And a true sphere placed by a similarity (turned, scaled by 1/4,
  // moved), which flattens into a sphere.
  Shape bead;
  bead.kind = Shape::Kind::Sphere;
  bead.material = ball.material;
  bead.center = vec3(0.4f, -0.3f, 0.2f);
  bead.radius = 0.8f;
  const mat4 similar = glm::translate(mat4(1.0f), vec3(0.3f, 0.35f, -0.4f)) *
                       glm::rotate(mat4(1.0f), 0.7f, glm::normalize(vec3(1.0f, 2.0f, 3.0f))) *
                       glm::scale(mat4(1.0f), vec3(0.25f));
  if (instanced) {
    bead.in_group = true;
    scene.groups.push_back({"bead", {static_cast<std::uint32_t>(scene.shapes.size())}});
    scene.shapes.push_back(bead);
    scene.instances.push_back({static_cast<std::uint32_t>(scene.groups.size() - 1), similar, "bead"});
  } else {
    bead.center = vec3(similar * vec4(bead.center, 1.0f));
    bead.radius *= 0.25f;
    scene.shapes.push_back(bead);
  }
  return scene;
}

// Same seed, same decisions: the samples agree but where a rounding
// difference between placing the hit and transforming the mesh flipped one.
// Both tracers: the wavefront's lanes place the balls' vertex normals (and
// make their frames) in their own resolve, transform_mesh is core's.
TEST(Instancing, RendersWhatTheFlattenedShapesRender) {
  for (const bool wavefront : {false, true}) {
    std::vector<FilmSample> samples[2];
    for (const bool instanced : {false, true}) {
      const Scene scene = cornell_with_balls(instanced);
      const RenderSettings settings = scene.render;
      const std::size_t n = static_cast<std::size_t>(scene.film.width) * scene.film.height * settings.spp;
      const CompiledScene compiled(scene);
      samples[instanced].resize(n);
      const auto spp = static_cast<std::uint32_t>(settings.spp);
      if (wavefront)
        WavefrontTracer(compiled, settings).render_batch(0, spp, samples[instanced]);
      else
        ReferenceTracer(compiled, settings).render_batch(0, spp, samples[instanced]);
    }
    std::size_t equal = 0, on_balls = 0;
    for (std::size_t i = 0; i < samples[0].size(); ++i) {
      const FilmSample &a = samples[0][i], &b = samples[1][i];
      bool same = a.hits == b.hits;
      for (int c = 0; c < 3; ++c)
        same = same && std::abs(a.L[c] - b.L[c]) <= 1e-4f * std::max(std::abs(a.L[c]), std::abs(b.L[c])) + 1e-6f;
      equal += same;
      on_balls += a.L != samples[0][0].L;
    }
    EXPECT_GE(static_cast<double>(equal), 0.99 * static_cast<double>(samples[0].size()))
        << (wavefront ? "wavefront: " : "reference: ") << samples[0].size() - equal << " of " << samples[0].size()
        << " samples differ";
    EXPECT_GT(on_balls, samples[0].size() / 2) << wavefront;
  }
}

// Both tracers, 1 and 2 threads, two wave sizes: the same image bits.
TEST(Instancing, SameBitsForAnyThreadCount) {
  Scene scene = test::cornell_with_instances();
  scene.film.width = scene.film.height = 20;
  scene.render.spp = 4;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  auto image = [&](int threads, bool wavefront, std::size_t wave) {
    const ThreadLimit limit(threads);
    Film film(20, 20, FilterKind::Box);
    if (wavefront) {
      const WavefrontTracer tracer(compiled, settings, wave);
      // The vectorised stages place hits on instances themselves, by the generic surface_point that
      // CompiledScene::resolve calls too.
      EXPECT_EQ(tracer.vectorised(), vector_stages::cpu_supported());
      render(tracer, film);
    } else {
      render(ReferenceTracer(compiled, settings), film);
    }
    return film.image();
  };
  for (const bool wavefront : {false, true}) {
    const Image a = image(1, wavefront, WavefrontTracer::kDefaultWaveSize), b = image(2, wavefront, 37);
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0) << wavefront;
  }
}

// trace-pixel names the instance a hit is on (JSON and text), and both
// tracers report the same one.
TEST(Instancing, TracedHitsNameTheirInstance) {
  Scene scene = test::cornell_with_instances();
  scene.film.width = scene.film.height = 24;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer wavefront(compiled, settings);
  std::set<std::uint32_t> seen;
  for (std::uint32_t y = 0; y < 24; y += 2)
    for (std::uint32_t x = 0; x < 24; x += 2) {
      PathRecorder a, b;
      reference.trace_sample(x, y, 0, &a);
      wavefront.trace_sample(x, y, 0, &b);
      EXPECT_TRUE(first_divergence(a.events(), b.events(), 1e-3f).rounding);
      for (const PathEvent& e : a.events()) {
        const auto* hit = std::get_if<HitEvent>(&e);
        if (hit == nullptr) continue;
        const bool in_group = compiled.scene().shapes[hit->shape].in_group;
        ASSERT_EQ(in_group, hit->instance != kNoInstance);
        const nlohmann::json j = path_to_json(TraceHeader{"t", "reference", x, y, 0, settings, 24, 24}, a, compiled.scene());
        if (!in_group) continue;
        seen.insert(hit->instance);
        EXPECT_NE(event_to_text(e, compiled.scene()).find(" instance " + std::to_string(hit->instance)), std::string::npos);
        bool named = false;
        for (const nlohmann::json& ev : j["events"])
          named = named || (ev["type"] == "hit" && ev["instance"] == hit->instance);
        EXPECT_TRUE(named) << j.dump();
      }
    }
  EXPECT_EQ(seen.size(), 3u);
}

// Rays leaving an instanced convex surface outwards never find it again,
// with placements far from the origin, turned and strongly scaled: the
// placed point's error bound covers what Embree does to the ray when it
// takes it into the group's space.
TEST(Instancing, NoSelfIntersectionOnFarTurnedScaledInstances) {
  Scene scene;
  scene.name = "far instances";
  scene.materials.push_back(diffuse_material(Spectrum(0.5f)));
  Shape ball;
  ball.in_group = true;
  ball.mesh = test::uv_sphere(vec3(0.0f), 1.0f, 12, false);
  scene.shapes.push_back(ball);
  scene.groups.push_back({"ball", {0}});
  const mat4 turn = glm::rotate(mat4(1.0f), 0.785f, glm::normalize(vec3(1, 2, 3)));
  std::vector<mat4> placements;
  for (const float far : {1e3f, 1e4f, 1e5f})
    for (const vec3 scale : {vec3(1.0f), vec3(1e-2f, 1e2f, 1.0f), vec3(-3.0f, 0.5f, 2.0f)})
      placements.push_back(glm::translate(mat4(1.0f), vec3(far, -0.7f * far, 0.3f * far)) * turn *
                           glm::scale(mat4(1.0f), scale));
  for (const mat4& m : placements) scene.instances.push_back({0, m, "far"});
  const CompiledScene compiled(std::move(scene));
  int self_hits = 0, rays = 0;
  for (std::uint32_t k = 0; k < placements.size(); ++k) {
    const vec3 centre = vec3(placements[k][3]);
    const float reach = 3.0f * glm::length(vec3(placements[k] * vec4(1, 1, 1, 0)));
    for (std::uint32_t i = 0; i < 300; ++i) {
      const vec2 u((static_cast<float>(i) + 0.5f) / 300.0f, std::fmod(0.618034f * static_cast<float>(i), 1.0f));
      const vec3 origin = centre + reach * square_to_uniform_sphere(u);
      Surfel s, again;
      if (!compiled.intersect(Ray{origin, glm::normalize(centre - origin), kInfinity}, &s) || s.instance != k) continue;
      for (std::uint32_t j = 0; j < 8; ++j) {
        vec3 w = square_to_cosine_hemisphere(vec2((static_cast<float>(j) + 0.5f) / 8.0f, u.x));
        if (j % 4 == 0) w = glm::normalize(vec3(w.x, w.y, 1e-3f));  // grazing
        ++rays;
        if (compiled.intersect(s.spawn(Frame(s.n).to_world(w)), &again) && again.instance == k) ++self_hits;
      }
    }
  }
  EXPECT_GT(rays, 5000);
  EXPECT_EQ(self_hits, 0) << "of " << rays << " rays";
}

// A scene built in code gets the loaders' checks when it is compiled.
TEST(Instancing, CompiledSceneRefusesBrokenInstancing) {
  const auto refused = [](Scene scene, const std::string& words) {
    try {
      const CompiledScene compiled(std::move(scene));
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  Scene bad = test::cornell_with_instances();
  bad.instances[1].group = 7;
  refused(bad, "instances[1] (pair): no group 7");
  bad = test::cornell_with_instances();
  bad.instances[2].to_world[0][0] = std::nanf("");
  refused(bad, "instances[2] (pair): the placement is singular or not finite");
  bad = test::cornell_with_instances();
  bad.instances[0].to_world = glm::scale(mat4(1.0f), vec3(1.0f, 0.0f, 1.0f));
  refused(bad, "singular");
  bad = test::cornell_with_instances();
  bad.groups[0].shapes.push_back(0);  // placed in the world, not in_group
  refused(bad, "group 'pair': shape 0 is not marked in_group");
}

TEST(Instancing, SceneFileGroupsAndInstances) {
  const Scene s = parse_scene(R"({"pathlab_scene": 1,
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": {"white": {"type": "diffuse"}, "glow": {"type": "diffuse", "emission": 1, "light": false}},
    "shapes": [{"type": "sphere", "material": "glow", "radius": 0.1}],
    "groups": {"pair": [{"type": "box", "material": "white", "transform": {"scale": 0.5}},
                        {"type": "sphere", "material": "glow", "center": [2, 0, 0]}]},
    "instances": [{"group": "pair", "transform": {"translate": [1, 2, 3]}},
                  {"group": "pair", "transforms": [[], [{"scale": [-1, 2, 1]}, {"translate": [0, 1, 0]}]]}]
  })", "instances.json");
  ASSERT_EQ(s.shapes.size(), 3u);
  EXPECT_FALSE(s.shapes[0].in_group);
  EXPECT_TRUE(s.shapes[1].in_group);
  EXPECT_TRUE(s.shapes[2].in_group);
  EXPECT_EQ(s.shapes[1].description, "groups/pair[0] (box)");
  EXPECT_EQ(s.shapes[2].center, vec3(2, 0, 0));  // in the group's space
  ASSERT_EQ(s.groups.size(), 1u);
  EXPECT_EQ(s.groups[0].shapes, (std::vector<std::uint32_t>{1, 2}));
  ASSERT_EQ(s.instances.size(), 3u);
  EXPECT_EQ(s.instances[0].description, "instances[0] (pair)");
  EXPECT_EQ(s.instances[2].description, "instances[1][1] (pair)");
  EXPECT_EQ(vec3(s.instances[0].to_world[3]), vec3(1, 2, 3));
  EXPECT_EQ(s.instances[1].to_world, mat4(1.0f));
  EXPECT_EQ(place(s.instances[2].to_world, vec3(1, 1, 1)), dvec3(-1, 3, 1));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  // The group's triangles are stored once, however often it is placed; an
  // emitter in a group that is not a light is found by rays only.
  const CompiledScene compiled(s);
  EXPECT_EQ(compiled.triangles().size(), 12u);
  EXPECT_EQ(compiled.lights().area_light_count(), 0u);
}

}  // namespace
}  // namespace pathlab
