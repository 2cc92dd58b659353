// EdgeList::mesh_edges lists where a mesh's radiance may jump: outlines and
// creases, each once, but not the diagonal inside a flat quad (two triangles
// sharing the edge by vertex index, in one plane, on one side, of one
// material), which expected_image() would otherwise refine for nothing.
#include "analytic-scenes/edges.h"

#include <gtest/gtest.h>

namespace pathlab {
namespace {

Shape quad(float lift = 0.0f) {
  Shape s;
  s.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, lift}, {0, 1, 0}};
  s.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return s;
}

std::size_t edge_count(const Shape& s) {
  EdgeList out(dvec3(0.5, 0.5, 5.0));
  out.mesh_edges(s);
  return out.arcs().size();
}

TEST(MeshEdges, AFlatQuadHasItsFourSidesOnly) { EXPECT_EQ(edge_count(quad()), 4u); }

TEST(MeshEdges, AFoldIsACrease) { EXPECT_EQ(edge_count(quad(0.25f)), 5u); }

TEST(MeshEdges, TwoMaterialsMeetAtTheDiagonal) {
  Shape s = quad();
  s.mesh.face_material = {0, 1};
  s.mesh.material_names = {"a", "b"};
  EXPECT_EQ(edge_count(s), 5u);
}

TEST(MeshEdges, TrianglesFacingOppositeWaysKeepTheEdge) {
  Shape s = quad();
  s.mesh.triangles = {{0, 1, 2}, {0, 3, 2}};  // the second one wound the other way
  EXPECT_EQ(edge_count(s), 5u);
}

TEST(MeshEdges, ADiagonalNotSharedByIndexIsKept) {
  // Split vertices (as an OBJ with a UV seam gives): the attributes may
  // differ on the two sides.
  Shape s = quad();
  s.mesh.positions.push_back({0, 0, 0});
  s.mesh.positions.push_back({1, 1, 0});
  s.mesh.triangles = {{0, 1, 2}, {4, 5, 3}};
  EXPECT_EQ(edge_count(s), 6u);
}

}  // namespace
}  // namespace pathlab
