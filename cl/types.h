// Data layouts shared by the host and the OpenCL kernels. Every struct here is stored in device
// buffers, so it uses only 4-byte scalars and 16-byte-aligned float4/int4 members: the layout is
// the same in OpenCL C and in C++ (checked by static_asserts on the host).
#ifndef CANOPY_CL_TYPES_H
#define CANOPY_CL_TYPES_H

#include "compat.h"

// ---------------------------------------------------------------- lights
#define LIGHT_POINT 0    // isotropic point: radiant intensity I [W/sr]
#define LIGHT_SPOT 1     // point with a cone: I [W/sr], axis, smooth (or hard) falloff
#define LIGHT_SPHERE 2   // spherical area light: radiance L [W/(m^2 sr)], radius r
#define LIGHT_QUAD 3     // parallelogram area light: radiance L, one- or two-sided
#define LIGHT_TRIANGLE 4 // triangle area light: radiance L (also every emissive mesh triangle)
#define LIGHT_DISK 5     // disk area light: radiance L, one- or two-sided
#define LIGHT_TYPE_COUNT 6
// Lights at infinity: not in the light tree nor in the power and uniform samplers. The device light
// buffer holds the scene's infinite lights after its light_count others, and every shading point
// samples each of them once (cl/integrator/light_pick.h, "lights at infinity").
// A distant light (the sun): parallel light from direction e1 (unit, towards the light) with
// irradiance E (emission) on a surface facing it.
#define LIGHT_DISTANT 6
// An environment light (the sky): radiance from every direction, emission times a map's texel
// (cl/lights/environment.h; flags: ENV_CONSTANT, no map, or the map's projection), in the map
// frame whose x, y, z axes are e1, e2, n (unit, orthonormal, world space). p.x, p.y, p.z: the bits
// of the map's first texel in the environment buffers, its width and its height (uint).
#define LIGHT_ENVIRONMENT 7
// Light::flags of an environment light: its map's projection (map frame e1, e2, n = x, y, z).
#define ENV_CONSTANT 0   // no map: radiance = emission
#define ENV_EQUIRECT 1   // u = phi / 2 pi from +x towards +y, v = theta / pi from +z (row 0 at +z)
#define ENV_OCTAHEDRAL 2 // pbrt-v4's EqualAreaSquareToSphere, z up; square maps only
// Infinite lights per scene at most: each shading point stages one shadow item per infinite light
// beside its own pick in the LIGHT_PICK_SHADOW_SLOTS (4) of its root item.
#define MAX_INFINITE_LIGHTS 3

#define LIGHT_FLAG_TWO_SIDED 1 // quad/triangle/disk emit on both faces
#define LIGHT_FLAG_FROM_MESH 2 // triangle is part of a mesh already in the geometry

typedef struct Light {
  // point/spot/sphere: position (xyz), sphere radius (w). quad: corner. triangle: v0. disk: centre
  // (xyz), radius (w). distant: unused.
  float4 p;
  // quad: edge 1; triangle: v1 - v0; spot: unit axis (xyz), cos of the cone half-angle rounded
  // down (w; a bound that only ever widens the cone, for the light tree). disk: unit tangent t1
  // (xyz) of the orthonormal frame (t1, t2, n), w unused. distant: unit direction towards the
  // light (xyz).
  float4 e1;
  // quad: edge 2; triangle: v2 - v0; spot: 1 - cos of the cone half-angle (x) and of the
  // falloff-start half-angle (y), both from 2 sin^2(angle / 2) in double (the falloff works in
  // 1 - cos, exact for narrow cones, cl/lights/light_sample.h); cos of the falloff start (w). disk:
  // unit tangent t2 = n x t1 (xyz), w unused.
  float4 e2;
  float4 n; // quad/triangle/disk: unit normal of the emitting face (xyz), area (w)
  // rgb: intensity (point/spot), radiance (area lights), irradiance (distant), radiance scale
  // (environment)
  float4 emission;
  int type;
  int flags;
  int prim; // first geometry primitive that shows this light (-1 for point/spot)
  int pad;
} Light;

// ---------------------------------------------------------------- materials
// Every glossy material uses GGX with alpha = roughness^2 (cl/bsdf/). alpha == 0 makes the glossy
// lobe a perfect mirror (a delta lobe: light sampling skips it).
#define MATERIAL_DIFFUSE 0   // Lambertian: albedo / pi
#define MATERIAL_CONDUCTOR 1 // GGX microfacet with the exact conductor Fresnel of eta + i k
#define MATERIAL_PLASTIC 2   // albedo / pi + specular * GGX with dielectric Fresnel (pbrt-v3)
// Glass (pbrt-v4's dielectric): Fresnel reflection and refraction of index `ior`, delta lobes at
// alpha 0, GGX microfacet lobes above. The thin one is a smooth sheet: rays pass straight through
// it, with the reflectance of its two faces and every inter-reflection between them (pbrt-v4's
// thindielectric).
#define MATERIAL_DIELECTRIC 3
#define MATERIAL_THIN_DIELECTRIC 4
// pbrt-v4's coateddiffuse and coatedconductor (cl/bsdf/layered.h): a dielectric coat of index
// `ior` and GGX alpha `alpha` over a Lambertian base of reflectance `albedo`, or over a conductor
// of index (specular + i k) / ior (the conductor's own index divided by the coat's) and GGX alpha
// `base_alpha`, with an optional scattering medium between them. Opaque, seen from the top only.
#define MATERIAL_COATED_DIFFUSE 5
#define MATERIAL_COATED_CONDUCTOR 6
// pbrt-v4's mix: one of two materials (mix_material) per shading point, the second with
// probability mix_amount (or its float texture's value there), chosen by a hash of the point and
// wo (cl/material_mix.h). Resolved before any BSDF use; never reaches the BSDF code.
#define MATERIAL_MIX 7
// pbrt-v4's diffusetransmission: reflectance albedo / pi on wo's side and transmittance
// `specular` / pi on the other (cl/bsdf/diffuse_transmission.h). Light reaches it from both
// sides.
#define MATERIAL_DIFFUSE_TRANSMISSION 8
// Mixes nest at most this deep (the loaders refuse deeper chains; the device resolves in a loop).
#define MATERIAL_MIX_MAX_DEPTH 8

typedef struct Material {
  float4 albedo;   // diffuse, plastic, coated diffuse: diffuse reflectance rgb in [0,1]
  float4 specular; // plastic: specular scale rgb; conductor, coated conductor: eta (real part of
                   // the conductor's index) rgb; diffuse transmission: transmittance rgb
  float4 k;        // conductor, coated conductor: k (imaginary part of the index) rgb
  float4 medium;   // coated: scattering albedo rgb of the layer between coat and base (0: it
                   // only absorbs); its Henyey-Greenstein g (w)
  float alpha;     // conductor, plastic, dielectric, coat: GGX alpha (0: perfect specular)
  float ior;       // plastic, coated: index of refraction of the coat; dielectrics: their index
                   // (the scene's, inside over outside; shade_surface inverts it from inside)
  int type;        // MATERIAL_*
  // Image textures (HAS_TEXTURES; cl/texture.h): 1 + the index into the scene's textures of the
  // texture that replaces albedo (rgb) and alpha (a float texture mapped to alpha, Texture::map);
  // 0: none, so a zero-initialised Material is untextured.
  int albedo_texture;
  int alpha_texture;
  // coated: the medium's thickness (its extinction coefficient is 1: pbrt-v4's sigma_t), the
  // conductor base's GGX alpha, the random walk's maximum depth and samples per evaluation.
  float thickness;
  float base_alpha;
  int max_depth;
  int n_samples;
  // 1: the surface bounds an object whose inside the scene's medium does not fill (glass in fog,
  // pbrt-v4's MediumInterface "" "fog"): a ray leaving into that inside travels outside the
  // medium (shade_surface.h).
  int excludes_medium;
  // mix: the two materials (indices into the scene's materials), the probability of choosing the
  // second and 1 + the index of the float texture that replaces it (0: none).
  int mix_material[2];
  float mix_amount;
  int mix_amount_texture;
  // diffuse transmission: 1 + the index of the texture that replaces `specular` (0: none).
  int transmittance_texture;
  int pad0;
} Material;

// ---------------------------------------------------------------- textures
// A texture is a small expression over the triangle's interpolated (u, v) (cl/texture.h): a tree
// of nodes stored in postfix order, each node right after its inputs' subtrees. A material refers
// to its root; the root's `nodes` counts the records of the whole tree (1 for an image alone), so
// the tree is the `nodes` records ending at the root. Evaluation keeps a stack of at most
// TEXTURE_STACK values (the loaders refuse deeper trees).
#define TEXTURE_IMAGE 0    // bilinearly filtered texels of one image, times `scale`
#define TEXTURE_CONSTANT 1 // `scale` itself (rgb; a float texture has x = y = z)
// pbrt-v4's 2D checkerboard on (s, t) = uvmap applied to (u, v): its first input where
// floor(s) + floor(t) is even, its second where it is odd (no antialiasing filter).
#define TEXTURE_CHECKERBOARD 2
#define TEXTURE_MIX 3   // pbrt-v4's mix: (1 - a) first + a second, a = the third input's x
#define TEXTURE_SCALE 4 // pbrt-v4's scale: the first input times the second
#define TEXTURE_STACK 8
// An image node's lookup: the image's row 0 is its top and t = 0 its bottom, as in pbrt-v4 and
// OBJ: texel coordinates are (s w, (1 - t) h) for (s, t) = uvmap applied to (u, v).
#define TEXTURE_WRAP_REPEAT 0 // s, t taken modulo 1
#define TEXTURE_WRAP_CLAMP 1  // texel coordinates clamped to the image
#define TEXTURE_WRAP_BLACK 2  // texels outside the image are 0
// What a float texture's value r means for GGX alpha (Texture::map of the root; rgb textures: 0).
#define TEXTURE_MAP_VALUE 0        // the value itself (rgb reflectance, or alpha)
#define TEXTURE_MAP_ALPHA_SQUARE 1 // Canopy's roughness: alpha = r^2 (scene.h conductor_material)
#define TEXTURE_MAP_ALPHA_SQRT 2   // pbrt-v4's remapped roughness: alpha = sqrt(r)

typedef struct Texture {
  float4 scale; // image: multiplies the filtered value (rgb; a float texture uses x); constant:
                // the value
  float4 uvmap; // image, checkerboard: (s, t) = (x u + z, y v + w): pbrt-v4's su, sv, du, dv
  int first;    // image: index in the texel buffer of the first channel of its first texel
  int width, height;
  int channels; // image: 3: rgb texels; 1: one float per texel
  int wrap;     // image: TEXTURE_WRAP_*
  int map;      // TEXTURE_MAP_* (read at the root)
  int kind;     // TEXTURE_*
  int nodes;    // records of the tree ending at this node (itself and its inputs' subtrees)
} Texture;

// ---------------------------------------------------------------- participating media
// A homogeneous medium (docs/scene-format.md "medium"; cl/volume/medium.h): coefficients per scene
// unit of length, a Henyey-Greenstein phase function, everywhere or inside an axis-aligned box
// (no surface: rays enter and leave it freely).
typedef struct Medium {
  float4 sigma_t; // rgb: sigma_a + sigma_s; w: Henyey-Greenstein g in (-1, 1)
  float4 sigma_s; // rgb: scattering coefficient; w: 1 if bounded by [bmin, bmax], 0 if unbounded
  float4 bmin;    // bounded: the box's minimum corner (xyz)
  float4 bmax;    // bounded: the box's maximum corner (xyz)
} Medium;

// ---------------------------------------------------------------- geometry / BVH
// A primitive is a triangle, a sphere or a disk. Vertices are stored with the primitive so the
// intersect kernel reads one contiguous record.
#define PRIM_TRIANGLE 0
#define PRIM_SPHERE 1
#define PRIM_DISK 2

typedef struct Primitive {
  float4 v0; // triangle: vertex 0 (xyz). sphere, disk: centre (xyz), radius (w).
  float4 e1; // triangle: v1 - v0. disk: unit normal (xyz). sphere: unused.
  float4 e2; // triangle: v2 - v0. sphere, disk: unused.
  int type;
  int material; // index into materials
  int light;    // index of the light this primitive shows, or -1
  // triangle with vertex normals: index of the first of its three shading normals (float4 xyz,
  // unit, in the order v0, v1, v2; cl/geometry.h primitive_shading_normal); -1: flat (or sphere)
  int normals;
} Primitive;

// BVH_WIDTH-wide BVH node (8: Embree's own width on AVX), struct of arrays in groups of four
// lanes: lane i = 4 g + k is element k of group g, so one node's boxes are tested four at a time
// with float4 arithmetic. child lane >= 0: an interior node; BVH_EMPTY: unused lane; other negative
// values: a leaf of the blocks leaf_blocks[first .. first + count), see bvh_leaf_*. An 8-wide tree
// has fewer levels than a 4-wide one, so a ray meets fewer dependent node loads; its 256-byte
// node spans four adjacent cache lines (cl/geometry.h bvh_node_lanes tests it as float8).
#define BVH_WIDTH 8
#define BVH_GROUPS (BVH_WIDTH / 4)
typedef struct BvhNode {
  float4 min_x[BVH_GROUPS], min_y[BVH_GROUPS], min_z[BVH_GROUPS];
  float4 max_x[BVH_GROUPS], max_y[BVH_GROUPS], max_z[BVH_GROUPS];
  int4 child[BVH_GROUPS];
  int4 pad[BVH_GROUPS]; // 128 bytes per group: a node spans whole cache lines
} BvhNode;

// Up to four primitives of a BVH leaf, stored in leaf order as a struct of arrays: lane i of each
// float4 is triangle i's v0, e1 = v1 - v0 and e2 = v2 - v0, so a leaf's triangles are tested at
// once with float4 arithmetic from contiguous memory (reading them through an index into the
// scene's primitives cost a cache miss per triangle). prim[i] is the lane's index into the scene's
// primitives; -1: an empty lane; -2 - p: primitive p is a sphere or a disk (its lane's edges are
// zero, so the triangle test misses it; the traversal tests prims[p] instead).
typedef struct LeafBlock {
  float4 v0_x, v0_y, v0_z;
  float4 e1_x, e1_y, e1_z;
  float4 e2_x, e2_y, e2_z;
  int4 prim;
} LeafBlock;

// ---------------------------------------------------------------- camera
typedef struct CameraParams {
  float4 origin;
  float4 lower_left; // world position of the image plane corner at distance 1
  float4 du;         // image plane step per pixel in x
  float4 dv;         // image plane step per pixel in y (downwards)
  int width;
  int height;
  int pad0, pad1;
} CameraParams;

// ---------------------------------------------------------------- wavefront records
typedef struct Hit {
  float t;
  int prim; // -1: miss
  float u, v;
} Hit;

// A shadow work item: a ray towards a sampled light point and the contribution it carries if the
// segment is unoccluded (throughput * BSDF * cos * Le / pdf already applied).
typedef struct ShadowItem {
  float4 origin;       // xyz origin, w: tmax
  float4 dir;          // xyz unit direction, w: path id (as int bits)
  float4 contribution; // rgb
} ShadowItem;

// One BRDF-aware sample of a glossy point (Liu et al. 2019, §4.2, §5), a work item of the BRDF
// rounds (cl/integrator/brdf_mis.h): a BRDF-oriented light sample (a shadow ray whose
// contribution is final unless occluded) or a BSDF sample (a probe ray whose contribution is known
// once its closest hit is: the emitter it finds, if any).
#define BRDF_ITEM_LIGHT 0
#define BRDF_ITEM_BSDF 1
typedef struct BrdfItem {
  float4 origin; // xyz origin, w: tmax (a BSDF probe: 0 = absorbed, nothing to trace)
  float4 dir;    // xyz unit direction, w: path id (as int bits)
  float4 value;  // light: rgb contribution; BSDF: beta f cos / N, to be weighted at the hit
  float4 extra;  // x: BSDF pdf, y: probability of choosing BRDF-oriented light sampling,
                 // z: BRDF_ITEM_*, w: 1 if the probe found an emitter (after brdf_trace)
} BrdfItem;

// A cluster of lights waiting in the split queue (Conty Estevez & Kulla 2018, Alg. 3 unrolled into
// passes): `code` is a light-tree node or leaf (cl/light_tree/layout.h), `sphere` and `cv2` its
// bounding sphere and energy CV^2 (the split measure's inputs), `budget` the cut size it may still
// spend.
typedef struct SplitItem {
  float4 sphere;
  int path;
  int code;
  uint budget;
  float cv2;
} SplitItem;

// Light samplers (compile-time CANOPY_LIGHT_SAMPLER in the kernels; a run-time value on the host).
#define SAMPLER_UNIFORM 0
#define SAMPLER_POWER 1
#define SAMPLER_TREE 2
#define SAMPLER_TREE_SPLIT 3
#define SAMPLER_EXHAUSTIVE 4
#define SAMPLER_BSDF 5 // no light sampling: emission is found by BSDF-sampled rays alone
// Liu, Xu & Yan 2019 at glossy points (tree-split elsewhere): BRDF-oriented light sampling, tree
// light sampling with splitting and BSDF sampling, MIS-combined with adaptive sample allocation.
#define SAMPLER_BRDF_MIS 6
#define SAMPLER_BRDF_ORIENTED 7 // BRDF-oriented light sampling alone at glossy points (ablation)

#endif // CANOPY_CL_TYPES_H
