// pbrt-v4 reader: the transform arithmetic of the graphics state (pbrt's current transformation
// matrix is a Transform, object space -> world, in double).
#pragma once

#include "scene/loader_internal.h"
#include "scene/pbrt/lexer.h"

#include <vector>

namespace canopy::pbrt {

using namespace detail;

// The inverse of x; ok is false (and the result unusable) when x is singular.
Transform inverse(const Transform& x, bool& ok);
// The linear part of x applied to the vector v.
double3 linear(const Transform& x, double3 v);
double dot3(double3 a, double3 b);
double3 cross3(double3 a, double3 b);
double len3(double3 a);

// The uniform scale of x if its linear part is a similarity (rotation, reflection and uniform
// scale), else 0: spheres and disks stay round only under those.
double similarity_scale(const Transform& x);

// pbrt's 4x4 matrices are written column by column (the format page, "Transformations": the
// translation is elements 12..14); the last row must be 0 0 0 1 for an affine transform.
Transform from_pbrt_matrix(const Loc& loc, const std::vector<double>& v);

} // namespace canopy::pbrt
