// The light tree's device layout (Conty Estevez & Kulla 2018, §4.1-4.2: a BVH of lights whose nodes
// hold bounding spheres, orientation cones and energies), the view LtTree the samplers read it
// through, leaf codes, emitter records and the octahedral decoding of cone axes. The build is
// host/light_tree/light_tree.cpp; importance.h, traverse.h, split.h and pmf.h read it. Compiles as
// OpenCL C and as C++ (cl/compat.h).
//
// The tree is 4-wide. Node `n` owns LT_NODE_F4 (8) consecutive float4 in `nodes` (struct of
// arrays: record k holds one quantity for the node's four children, lane i = child i; 128 bytes)
// and one int4 in `children`:
//   nodes[n*8 + 0..2]  LT_CX, LT_CY, LT_CZ   bounding-sphere centre of each child
//   nodes[n*8 + 3]     LT_R                  bounding-sphere radius (sphere of the child's bbox)
//   nodes[n*8 + 4]     LT_AXIS               orientation cone axis, octahedral, 2 x 16 bits (the
//                                            bits of the float; lt_oct_decode_v)
//   nodes[n*8 + 5]     LT_COS_O              cos(theta_o) (normal bound), widened by the axis
//                                            quantisation error and rounded down; LT_PLANE_FLAG
//                                            (2): a lane of one-sided planar emitters with a
//                                            half-space bound, theta_o = LT_PLANE_SLOPE
//   nodes[n*8 + 6]     LT_ENERGY             sum of emitter energies (luminance of max intensity)
//   nodes[n*8 + 7]     LT_CE_CV2             bits 0-15: cos(theta_e) * 65535 rounded down
//                                            (emission bound, theta_e <= pi/2), or for a
//                                            LT_PLANE_FLAG lane (theta_e = pi/2) the plane offset
//                                            k: h = (k - 32768) r 2^-14; bits 16-31: the
//                                            high half of the float V[e]/E[e]^2 (squared
//                                            coefficient of variation of the energies, splitting)
//   children[n].lane   >= 0: index of a child node (the child nodes of a node are consecutive)
//                      LT_EMPTY: unused lane (its energy is 0)
//                      other < 0: leaf, code = -1 - child = (first << 2) | (count - 1): the
//                      emitters leaf_lights[first .. first+count), count in 1..4
// Node 0 is the root. After the num_nodes * 8 node records, `nodes` holds one emitter record of
// LT_EMITTER_F4 (2) float4 per emitter in leaf order (index first + j), starting at float4 index
// lt_emitter_base() (root_info.z holds its bits plus LT_EMITTER_BASE_BIAS):
//   record[0]  bounding sphere of the emitter (centre, radius), as in the nodes
//   record[1]  x: octahedral axis bits; y: cone q (q <= 1: cos(theta_o), theta_e = pi/2; q > 1.5:
//              theta_o = 0, cos(theta_e) = q - 2; widened by the axis quantisation error;
//              q < -1.5: one-sided planar, theta_o = LT_PLANE_SLOPE, theta_e = pi/2, half-space
//              bound h = (-2 - q) r); z: energy; w: bits of the light index
//              (= leaf_lights[first + j])
// so a leaf is ranked from its records without touching the scene's Light buffer. The tree costs
// 52-61 bytes/emitter. trails[light]: the light's bit-trail, 2 bits per 4-wide level starting with
// the root in the two lowest bits, then 2 bits for its index inside its leaf. root_sphere /
// root_info: bounding sphere of all emitters; (cv2, total energy, emitter record base, importance
// terms: LT_TERMS_FULL or LT_TERMS_DISTANCE).
#ifndef CANOPY_LIGHT_TREE_LAYOUT_H
#define CANOPY_LIGHT_TREE_LAYOUT_H

#include "../compat.h"
#include "../simd4.h"
#include "../types.h"

#define LT_NODE_F4 8
#define LT_CX 0
#define LT_CY 1
#define LT_CZ 2
#define LT_R 3
#define LT_AXIS 4
#define LT_COS_O 5
#define LT_ENERGY 6
#define LT_CE_CV2 7

// Emitter records: LT_EMITTER_F4 float4 per emitter, in leaf order, after the node records.
#define LT_EMITTER_F4 2
#define LT_EMITTER_BASE_BIAS 0x40000000u
#define LT_OCT_SCALE 3.0518044e-05f /* 2 / 65535 */
#define LT_U16_SCALE 1.5259022e-05f /* 1 / 65535 */

#define LT_EMPTY (-2147483647 - 1)
#define LT_MAX_LEAF 4
// 4-wide node levels below the root (inclusive) so that 2 bits per level + 2 leaf bits fit a uint.
#define LT_MAX_NODE_LEVELS 15
// Importance terms (root_info.w). LT_TERMS_DISTANCE drops the orientation factors of Eq. 3 (the
// emitter cone cos(theta') and the receiver cos(theta_i')) and keeps E / d^2: the ablation of the
// paper's Fig. 15-16 ("distance" against "distance + orientation"). The tree itself is unchanged.
#define LT_TERMS_FULL 0.0f
#define LT_TERMS_DISTANCE 1.0f
// Half-space bound of one-sided planar emitters (quads, triangles, mesh triangles): such an emitter
// sends nothing to a point on or behind its plane. A lane with a plane offset h (the emitters of
// the lane all lie on the front side of the plane through c - h a, a = the lane's decoded axis) is
// culled at P when dot(a, P - c) <= -(h + LT_PLANE_SLOPE |P - c|), c = the lane's sphere centre.
// The slope covers the angle between a and every emitter's own normal (octahedral quantisation,
// and for a node the spread of its emitters' normals: nodes qualify when it is below
// LT_PLANE_SLOPE - LT_PLANE_ROUND) plus the float rounding of the test (LT_PLANE_ROUND, relative
// to |P - c|); h absorbs the rest (the emitters' extent below c, the rounding of their sample
// points). Such lanes have the cone theta_o = LT_PLANE_SLOPE, theta_e = pi/2.
#define LT_PLANE_SLOPE 2.4414062e-04f /* 2^-12 */
#define LT_PLANE_ROUND 3.8146973e-06f /* 2^-18 */
#define LT_PLANE_COS_O 0.99999994f    /* cos(2^-12) rounded down */
#define LT_PLANE_NONE 3.0e38f         /* h of a lane without a plane: never culls */
// Node lanes with a plane: LT_COS_O holds LT_PLANE_FLAG (> 1, no cosine) and the low 16 bits of
// LT_CE_CV2 hold k, h = (k - 32768) * (r * LT_PLANE_H_UNIT) (theta_e = pi/2 needs no bits).
#define LT_PLANE_FLAG 2.0f
#define LT_PLANE_H_UNIT 6.1035156e-05f /* 2^-14 */

// A view of the tree buffers (kernel: build it from the kernel arguments in private memory).
typedef struct LtTree {
  GLOBAL const float4* nodes;    // LT_NODE_F4 per node
  GLOBAL const int4* children;   // one per node
  GLOBAL const int* leaf_lights; // light indices in leaf order
  GLOBAL const uint* trails;     // per light index
  GLOBAL const Light* lights;    // the scene's lights
  float4 root_sphere;            // bounding sphere of all emitters
  float4 root_info;              // x: energy CV^2, y: total energy
} LtTree;

INLINE int lt_is_leaf(int code) {
  return code < 0 && code != LT_EMPTY;
}
INLINE int lt_leaf_first(int code) {
  return (-1 - code) >> 2;
}
INLINE int lt_leaf_count(int code) {
  return ((-1 - code) & 3) + 1;
}
INLINE int lt_leaf_code(int first, int count) {
  return -1 - ((first << 2) | (count - 1));
}

// Emitter records (see the top of the file): float4 index of the first one.
INLINE uint lt_emitter_base(const LtTree* t) {
  return float_as_uint_(t->root_info.z) - LT_EMITTER_BASE_BIAS;
}
INLINE GLOBAL const float4* lt_emitter_records(const LtTree* t, int first) {
  return t->nodes + lt_emitter_base(t) + (uint)first * LT_EMITTER_F4;
}
// Octahedral unit vectors from their two 16-bit fixed-point coordinates u, v (as floats,
// 0..65535; stored as the low and high halves of a float's bits), normalised.
LT_HOT void lt_oct_decode_v(v4f u, v4f v, v4f* ax, v4f* ay, v4f* az) {
  v4f one = v4_splat(1.0f);
  v4f zero = v4_splat(0.0f);
  v4f x = v4_sub(v4_mul(u, v4_splat(LT_OCT_SCALE)), one);
  v4f y = v4_sub(v4_mul(v, v4_splat(LT_OCT_SCALE)), one);
  v4f abs_x = v4_max(x, v4_sub(zero, x));
  v4f abs_y = v4_max(y, v4_sub(zero, y));
  v4f z = v4_sub(v4_sub(one, abs_x), abs_y);
  v4m fold = v4_lt(z, zero);
  v4f tx = v4_sel(v4_sub(abs_y, one), v4_sub(one, abs_y), v4_ge(x, zero));
  v4f ty = v4_sel(v4_sub(abs_x, one), v4_sub(one, abs_x), v4_ge(y, zero));
  x = v4_sel(x, tx, fold);
  y = v4_sel(y, ty, fold);
  v4f inv = v4_div(one, v4_sqrt(v4_add(v4_add(v4_mul(x, x), v4_mul(y, y)), v4_mul(z, z))));
  *ax = v4_mul(x, inv);
  *ay = v4_mul(y, inv);
  *az = v4_mul(z, inv);
}
// The same on float4 (the build encodes with it; tests decode with it).
LT_HOT void lt_oct_decode4(float4 u, float4 v, float4* ax, float4* ay, float4* az) {
  v4f x, y, z;
  lt_oct_decode_v(v4_from_f4(u), v4_from_f4(v), &x, &y, &z);
  *ax = v4_to_f4(x);
  *ay = v4_to_f4(y);
  *az = v4_to_f4(z);
}

// The orientation ablation (LT_TERMS_DISTANCE): a cone of half-angle pi around any axis bounds
// The low / high 16 bits of the bit patterns of four floats, as floats (exact; the node and
// emitter records pack two 16-bit values in one float's bits).
INLINE float4 lt_lo16_4(float4 bits) {
  return v4_to_f4(v4_lo16(v4_from_f4(bits)));
}
INLINE float4 lt_hi16_4(float4 bits) {
  return v4_to_f4(v4_hi16(v4_from_f4(bits)));
}

#endif // CANOPY_LIGHT_TREE_LAYOUT_H
