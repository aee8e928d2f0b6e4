// Image textures (cl/types.h Texture): bilinear lookup, as pbrt-v4's ImageTexture with its default
// "bilinear" filter (one level, no MIP maps), and a material's textured albedo and alpha at a
// triangle hit. Compiled into the kernels only for scenes with a textured material (HAS_TEXTURES).
#ifndef CANOPY_CL_TEXTURE_H
#define CANOPY_CL_TEXTURE_H

#include "compat.h"
#include "types.h"

// The two texels along one axis of n texels that a bilinear lookup at coordinate s (texture space,
// [0, 1] across the image) blends, and the weight f of the second: texel centres sit at
// (i + 0.5) / n. An index is -1 where TEXTURE_WRAP_BLACK leaves the image. Non-finite s reads
// texel 0 (no NaN reaches an index).
INLINE void texture_axis(float s, int n, int wrap, int* i0, int* i1, float* f) {
  if (!is_finite_f(s)) s = 0.0f;
  // Repeat: only the fraction matters; taking it first keeps s n - 0.5 small (no int overflow).
  if (wrap == TEXTURE_WRAP_REPEAT) s = s - floor(s);
  float x = s * (float)n - 0.5f;
  x = fmin(fmax(x, -1.0f), (float)n); // clamp and black: beyond one texel outside all is alike
  float x0 = floor(x);
  *f = x - x0;
  int a = (int)x0, b = a + 1;
  if (wrap == TEXTURE_WRAP_REPEAT) {
    a = a < 0 ? a + n : (a >= n ? a - n : a);
    b = b < 0 ? b + n : (b >= n ? b - n : b);
  } else if (wrap == TEXTURE_WRAP_CLAMP) {
    a = min(max(a, 0), n - 1);
    b = min(max(b, 0), n - 1);
  } else {
    a = a < 0 || a >= n ? -1 : a;
    b = b < 0 || b >= n ? -1 : b;
  }
  *i0 = a;
  *i1 = b;
}

// Texel (x, y) (row 0 at the image's top) as rgb; a one-channel texture gives its value thrice.
INLINE float3 texture_texel(GLOBAL const Texture* t, GLOBAL const float* texels, int x, int y) {
  if (x < 0 || y < 0) return make_float3(0.0f, 0.0f, 0.0f);
  int k = t->first + (y * t->width + x) * t->channels;
  if (t->channels == 1) return make_float3(texels[k], texels[k], texels[k]);
  return make_float3(texels[k], texels[k + 1], texels[k + 2]);
}

// The texture's bilinearly filtered value at (u, v), times its scale. v = 0 is the image's
// bottom row (pbrt-v4 flips t: its ImageTexture looks up (s, 1 - t)).
INLINE float3 texture_lookup(GLOBAL const Texture* t, GLOBAL const float* texels, float2 uv) {
  float s = t->uvmap.x * uv.x + t->uvmap.z;
  float tt = 1.0f - (t->uvmap.y * uv.y + t->uvmap.w);
  int x0, x1, y0, y1;
  float fx, fy;
  texture_axis(s, t->width, t->wrap, &x0, &x1, &fx);
  texture_axis(tt, t->height, t->wrap, &y0, &y1, &fy);
  float3 c = texture_texel(t, texels, x0, y0) * ((1.0f - fx) * (1.0f - fy)) +
             texture_texel(t, texels, x1, y0) * (fx * (1.0f - fy)) +
             texture_texel(t, texels, x0, y1) * ((1.0f - fx) * fy) +
             texture_texel(t, texels, x1, y1) * (fx * fy);
  return c * xyz_of(t->scale);
}

// GGX alpha from a float texture's value r (TEXTURE_MAP_*), at most 1 (Canopy's GGX range, as the
// scene readers clamp constant roughness); a negative or NaN r gives 0 (a mirror).
INLINE float texture_alpha(int map, float r) {
  r = r > 0.0f ? r : 0.0f;
  float a = map == TEXTURE_MAP_ALPHA_SQUARE ? r * r : (map == TEXTURE_MAP_ALPHA_SQRT ? sqrt(r) : r);
  return fmin(a, 1.0f);
}

// The texture coordinates at barycentrics (bu, bv) of scene triangle `tri` (three uv per triangle
// in `texcoords`, at v0, v1, v2).
INLINE float2 triangle_uv(GLOBAL const float2* texcoords, int tri, float bu, float bv) {
  float2 a = texcoords[3 * tri], b = texcoords[3 * tri + 1], c = texcoords[3 * tri + 2];
  float w = 1.0f - bu - bv;
  return make_float2(w * a.x + bu * b.x + bv * c.x, w * a.y + bu * b.y + bv * c.y);
}

// Replaces the albedo and alpha of `m`, the material of scene triangle `tri` hit at barycentrics
// (bu, bv), by its textures' values there (albedo clamped to [0, 1]). Only textured materials call it (Material's
// albedo_texture, alpha_texture: 1 + a texture index), and only scene triangles have them.
INLINE void material_apply_textures(Material* m, GLOBAL const float2* texcoords,
                                    GLOBAL const Texture* textures, GLOBAL const float* texels,
                                    int tri, float bu, float bv) {
  float2 uv = triangle_uv(texcoords, tri, bu, bv);
  if (m->albedo_texture > 0) {
    // A reflectance above 1 would create energy: clamped to [0, 1] as pbrt-v4's materials do.
    float3 a = texture_lookup(&textures[m->albedo_texture - 1], texels, uv);
    a = fmin(fmax(a, make_float3(0.0f, 0.0f, 0.0f)), make_float3(1.0f, 1.0f, 1.0f));
    m->albedo = f4_from3(a, 0.0f);
  }
  if (m->alpha_texture > 0) {
    GLOBAL const Texture* t = &textures[m->alpha_texture - 1];
    m->alpha = texture_alpha(t->map, texture_lookup(t, texels, uv).x);
  }
}

#endif // CANOPY_CL_TEXTURE_H
