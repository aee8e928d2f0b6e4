// Loop subdivision (host/scene/loop_subdivision.cpp) of input it cannot subdivide: each is a
// one-line SceneError saying what is wrong.
#include "scene/loop_subdivision.h"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <string>
#include <vector>

using canopy::SceneError;
using canopy::detail::loop_subdivide;

namespace {

// Four points and the triangles of a tetrahedron on them, wound consistently.
const std::vector<float3> kP = {make_float3(0, 0, 0), make_float3(1, 0, 0), make_float3(0, 1, 0),
                                make_float3(0, 0, 1), make_float3(1, 1, 1)};
const std::vector<uint32_t> kTetrahedron = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

void expect_error(const std::vector<float3>& P, const std::vector<uint32_t>& indices, int levels,
                  const std::string& part) {
  try {
    loop_subdivide(P, indices, levels);
    ADD_FAILURE() << "no error; expected one with \"" << part << "\"";
  } catch (const SceneError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

} // namespace

TEST(LoopSubdivisionErrors, EdgeOfThreeTriangles) {
  expect_error(kP, {0, 1, 2, 1, 0, 3, 0, 1, 4}, 1,
               "the edge between vertices 0 and 1 is shared by 3 triangles");
}

TEST(LoopSubdivisionErrors, InconsistentWinding) {
  expect_error(kP, {0, 1, 2, 0, 1, 3}, 1,
               "the two triangles on the edge between vertices 0 and 1 are wound in opposite");
}

// Two triangles that touch at vertex 0 only: its neighbourhood is not a disc.
TEST(LoopSubdivisionErrors, VertexOfTwoFans) {
  std::vector<float3> P = kP;
  P.push_back(make_float3(-1, -1, 0));
  expect_error(P, {0, 1, 2, 0, 4, 5}, 0, "the triangles at vertex 0 do not form a single fan");
}

TEST(LoopSubdivisionErrors, IndexOutOfRange) {
  expect_error(kP, {0, 1, 5}, 1, "index 5 is out of range (5 vertices)");
}

TEST(LoopSubdivisionErrors, TriangleRepeatsAVertex) {
  expect_error(kP, {0, 1, 2, 2, 1, 1}, 1, "triangle 1 (2 1 1) repeats a vertex");
}

TEST(LoopSubdivisionErrors, IndexCountAndNoTriangles) {
  expect_error(kP, {0, 1, 2, 3}, 1, "4 indices is not a multiple of 3");
  expect_error(kP, {}, 1, "no triangles");
}

TEST(LoopSubdivisionErrors, NonFinitePosition) {
  std::vector<float3> P = kP;
  P[3].y = NAN;
  expect_error(P, kTetrahedron, 1, "vertex 3 is not finite");
}

// 4 triangles x 4^12 = 2^26 is within the limit of 2^27; 4^13 x 4 = 2^28 is not (only the former
// is not run here: it would take a while).
TEST(LoopSubdivisionErrors, TooManyLevels) {
  expect_error(kP, kTetrahedron, 13,
               "13 levels of subdivision of 4 triangles give more than 134217728 triangles");
  expect_error(kP, kTetrahedron, INT_MAX, "give more than 134217728 triangles");
  expect_error(kP, kTetrahedron, -1, "levels -1 is negative");
}
