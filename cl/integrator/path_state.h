// Per-path state of the wavefront (struct of arrays, indexed by path id) and the scene buffers, as
// structs of pointers so the per-item stage functions take them in one argument on both the device
// (where the kernels assemble them from their arguments, see cl/kernels/params.h) and the host.
#ifndef CANOPY_INTEGRATOR_PATH_STATE_H
#define CANOPY_INTEGRATOR_PATH_STATE_H

#include "../kernel_features.h"
#include "../types.h"

// The path state, one line per buffer: X(element type, name). The name is the PathBuffers field,
// the kernel parameter (PATH_PARAMS, cl/kernels/params.h) and the host's argument name; the
// renderer allocates one element per path of a wave for each. Adding a buffer is one line here.
// clang-format off
#define PATH_STATE_BUFFERS(X)                                                                      \
  X(float4, ray_o)      /* xyz: origin, w: tmin */                                                 \
  /* xyz: unit direction, w: 1 if the ray travels inside an object that excludes the medium */  \
  /* (Material.excludes_medium), else 0 */                                                     \
  X(float4, ray_d)                                                                                 \
  X(float4, throughput) /* xyz: path throughput beta */                                            \
  X(float4, radiance)   /* xyz: radiance gathered so far */                                        \
  X(uint4, rng)         /* the path's sampler state (cl/sampler.h) */                              \
  /* sobol (cl/sampler.h): the shading point's light-point numbers, written by shade_surface for */ \
  /* every light sample of light_pick at that point */                                            \
  X(float2, light_u)                                                                               \
  X(Hit, hits)          /* closest hit of the current ray */                                       \
  /* The last shading point, kept for light picking in this bounce and for MIS at the next hit. */ \
  /* xyz: position (the ray origin of rays leaving it, offset from the surface, cl/shading.h), */  \
  /* w: solid-angle pdf of the BSDF direction that left it (0: delta) */                                  \
  X(float4, shade_P)                                                                               \
  /* xyz: geometric normal facing wo, w: light-pick seed (uint bits) */                           \
  X(float4, shade_N)                                                                               \
  /* xyz: path throughput beta at the shading point, w: 1 if light samples are MIS-weighted */     \
  /* against BSDF sampling (the path continues with a BSDF sample and MIS is on), else 0; */       \
  /* BRDF_POINT_FLAG (2): a glossy point of a BRDF sampler (brdf_mis.h) */                        \
  X(float4, shade_f)                                                                               \
  /* xyz: unit direction towards the viewer (read for glossy materials only), w: ray_d.w of the */ \
  /* ray that arrived (1: the point lies outside the medium) */                                 \
  X(float4, shade_wo)                                                                              \
  /* xyz: shading normal (on wo's side; the geometric normal when flat), w: material (int bits) */ \
  X(float4, shade_Ns)                                                                              \
  /* With image textures: the textured material's albedo (xyz) and alpha (w) at the shading */     \
  /* point (shading_point_material), written only where its material has a texture */              \
  X(float4, shade_tex)                                                                             \
  /* With a diffuse-transmission material's transmittance texture: its value there (xyz) */       \
  X(float4, shade_tex_t)                                                                           \
  /* With diffuse transmission (HAS_MATERIAL_DIFFUSE_TRANSMISSION): xyz: the origin of rays */    \
  /* leaving the shading point on the far side of the surface, w: 1 if light reaches the point */ \
  /* from both sides (bsdf_two_sided), else 0 */                                                  \
  X(float4, shade_back)                                                                            \
  /* brdf-mis, brdf-oriented (brdf_mis.h): x: cut size, y: BRDF-aware samples N (-1: a glossy */   \
  /* point whose cut is not built yet), z: samples drawn, w: n_hit | n_nohit << 16 (Alg. 1) */     \
  X(int4, brdf_state)                                                                              \
  /* brdf-mis: the share of BRDF-oriented light samples the tree sample's MIS weight assumes */    \
  X(float, brdf_share)                                                                             \
  /* With a medium (shade_volume.h): this bounce's ray segment inside the medium. xyz: its start */ \
  /* (where the ray enters the medium), w: its length, < 0 when it gets no light samples */          \
  X(float4, seg_o)                                                                                 \
  /* xyz: its unit direction, w: the free-flight distance sampled along it (from its start) */     \
  X(float4, seg_d)                                                                                 \
  /* xyz: the path throughput at its start, w: the segment's light-pick seed (uint bits) */        \
  X(float4, seg_beta)                                                                              \
  /* 1 if the path continues from this segment's free-flight point with a phase-function ray */  \
  /* and MIS is on (the segment's light samples are weighted against that technique), else 0 */  \
  X(float, seg_phase)                                                                              \
  /* The segment of the path's last medium vertex (shade_P), for MIS at the next hit: */          \
  /* xyz: its start, w: its length; and xyz: its direction, w: the vertex's distance along it */  \
  X(float4, scatter_seg_o)                                                                         \
  X(float4, scatter_seg_d)

// The scene's buffers, likewise: X(element type, name), read-only on the device.
#define SCENE_BUFFERS(X)                                                                           \
  X(BvhNode, nodes)                                                                                \
  X(LeafBlock, leaf_blocks)                                                                        \
  X(Primitive, prims)                                                                              \
  X(Material, materials)                                                                           \
  /* three unit vertex normals per smooth triangle (Primitive.normals, cl/geometry.h) */            \
  X(float4, shading_normals)                                                                       \
  /* the scene's participating medium (one record; zeros without one) */                          \
  X(Medium, medium)                                                                                \
  /* Image textures (cl/texture.h): with a textured material, three uv per scene triangle (at */    \
  /* v0, v1, v2; primitive t < the triangle count is triangle t), the textures and their texels */ \
  X(float2, texcoords)                                                                             \
  X(Texture, textures)                                                                             \
  X(float, texels)
// clang-format on

#define CANOPY_PATH_FIELD(T, name) GLOBAL T* name;
#define CANOPY_SCENE_FIELD(T, name) GLOBAL const T* name;

typedef struct PathBuffers {
  PATH_STATE_BUFFERS(CANOPY_PATH_FIELD)
} PathBuffers;

typedef struct SceneBuffers {
  SCENE_BUFFERS(CANOPY_SCENE_FIELD)
} SceneBuffers;

// The normal a shading point's light-tree queries bound the receiver's cosine with (Conty Estevez
// & Kulla 2018, Eq. 3's theta_i): the shading normal, the one whose cosine the BSDF applies
// (light_point.h). With the geometric normal, lights near the geometric horizon of a smooth-shaded
// mesh got a far smaller pmf than their contribution (fireflies at silhouettes). The bound stays
// conservative: a direction below the shading horizon contributes nothing, and one below the
// geometric surface is rejected besides (as pbrt-v4's LightSampleContext, which carries ns).
// shade_surface, light_pick and the BRDF-oriented cut all read it here, so their pmfs agree.
// At a point that light reaches from both sides (diffuse transmission) the queries carry no normal
// (N = 0, no receiver term): a one-sided bound would cull the lights behind the surface.
INLINE float3 light_query_normal(const PathBuffers* pb, int path) {
  if (HAS_MATERIAL_DIFFUSE_TRANSMISSION ? pb->shade_back[path].w != 0.0f : 0)
    return make_float3(0.0f, 0.0f, 0.0f);
  return xyz_of(pb->shade_Ns[path]);
}

// The normal environment lights are sampled about at the shading point (a constant sky by the
// cosine, cl/lights/environment.h): the shading normal, on both kinds of point. At a two-sided
// point such a sky is then sampled on wo's side only; its pdf is 0 beyond, where BSDF rays that
// escape take weight 1 (shade_environment_weight).
INLINE float3 env_query_normal(const PathBuffers* pb, int path) {
  return xyz_of(pb->shade_Ns[path]);
}

// Whether the shading point of `path` takes light from both sides of its surface.
INLINE int shading_point_two_sided(const PathBuffers* pb, int path) {
  return HAS_MATERIAL_DIFFUSE_TRANSMISSION ? pb->shade_back[path].w != 0.0f : 0;
}

// The material at the path's shading point: the scene's material (a mix already resolved to the
// one chosen there, cl/material_mix.h), with the textured albedo, alpha and transmittance that
// shade_surface looked up at the hit (cl/texture.h) where it has textures.
INLINE Material shading_point_material(const SceneBuffers* sc, const PathBuffers* pb, int path) {
  Material m = sc->materials[(int)float_as_uint_(pb->shade_Ns[path].w)];
  if (HAS_TEXTURES ? (m.albedo_texture | m.alpha_texture) != 0 : 0) {
    float4 t = pb->shade_tex[path];
    m.albedo = f4_from3(xyz_of(t), 0.0f);
    m.alpha = t.w;
  }
#if HAS_TEXTURES && HAS_MATERIAL_DIFFUSE_TRANSMISSION
  if (m.transmittance_texture != 0) m.specular = f4_from3(xyz_of(pb->shade_tex_t[path]), 0.0f);
#endif
  return m;
}

// Whether the camera ray of a path (depth 0) hits an emitter: the pixels whose error is measured
// apart (`canopy converge`), since their noise is the anti-aliasing of the emitter's edge, not
// light sampling. Read before shade_volume can replace the hit by a scattering event.
INLINE int camera_ray_hits_emitter(int depth, Hit h, const SceneBuffers* sc) {
  return depth == 0 && h.prim >= 0 && sc->prims[h.prim].light >= 0;
}

#endif // CANOPY_INTEGRATOR_PATH_STATE_H
