// A closed mesh for watertightness checks: the icosahedron subdivided
// `subdivisions` times (20 * 4^subdivisions triangles) and projected onto
// the unit sphere. Every edge is shared by exactly
// two triangles through the same two vertex indices, so a ray from inside
// can leave only through a crack in the intersection test itself.
#pragma once

#include "core/mesh.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace pathlab::test {

inline TriangleMesh icosphere(int subdivisions) {
  TriangleMesh m;
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  const double corners[12][3] = {{-1, g, 0}, {1, g, 0},   {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                                 {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  std::vector<dvec3> p;
  for (const auto& c : corners) p.push_back(glm::normalize(dvec3(c[0], c[1], c[2])));
  std::vector<glm::uvec3> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9},   {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> middle;
    const auto mid = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = middle.try_emplace(key, static_cast<unsigned>(p.size()));
      if (added) p.push_back(glm::normalize(p[a] + p[b]));
      return it->second;
    };
    std::vector<glm::uvec3> next;
    for (const glm::uvec3& f : t) {
      const unsigned ab = mid(f.x, f.y), bc = mid(f.y, f.z), ca = mid(f.z, f.x);
      next.insert(next.end(), {{f.x, ab, ca}, {f.y, bc, ab}, {f.z, ca, bc}, {ab, bc, ca}});
    }
    t = std::move(next);
  }
  for (const dvec3& q : p) m.positions.push_back(vec3(q));
  m.triangles = std::move(t);
  return m;
}

}  // namespace pathlab::test
