// Textures (cl/types.h Texture): image nodes looked up bilinearly, as pbrt-v4's ImageTexture with
// its default "bilinear" filter (one level, no MIP maps), constants, and pbrt-v4's checkerboard,
// mix and scale over them, evaluated as a postfix program; and a material's textured values at a
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

// The parity of floor(x) (0 even, 1 odd) without an int conversion that could overflow; a
// non-finite x counts as even.
INLINE int texture_floor_odd(float x) {
  if (!is_finite_f(x)) return 0;
  float f = floor(x);
  return f - 2.0f * floor(0.5f * f) != 0.0f;
}

// pbrt-v4's 2D checkerboard weight of its second input at (u, v): 0 where floor(s) + floor(t) is
// even, 1 where it is odd ((s, t) = the node's uv mapping). pbrt-v4 box-filters the edges with the
// ray differentials' footprint; without differentials (Canopy has none) its weight is this.
INLINE float texture_checker_weight(GLOBAL const Texture* t, float2 uv) {
  float s = t->uvmap.x * uv.x + t->uvmap.z;
  float tt = t->uvmap.y * uv.y + t->uvmap.w;
  return (texture_floor_odd(s) ^ texture_floor_odd(tt)) ? 1.0f : 0.0f;
}

// The value at (u, v) of the texture whose root is textures[root] (its tree is the root's `nodes`
// records ending at it, in postfix order: every node pops its inputs and pushes its value).
INLINE float3 texture_eval(GLOBAL const Texture* textures, GLOBAL const float* texels, int root,
                           float2 uv) {
  float3 stack[TEXTURE_STACK];
  int top = 0;
  // (a zero-initialised record, nodes 0, is an image alone)
  const int first = root - max(textures[root].nodes, 1) + 1;
  for (int i = first; i <= root; ++i) {
    GLOBAL const Texture* t = &textures[i];
    float3 v;
    if (t->kind == TEXTURE_IMAGE) {
      v = texture_lookup(t, texels, uv);
    } else if (t->kind == TEXTURE_CONSTANT) {
      v = xyz_of(t->scale);
    } else if (t->kind == TEXTURE_CHECKERBOARD) {
      top -= 2;
      v = texture_checker_weight(t, uv) > 0.0f ? stack[top + 1] : stack[top];
    } else if (t->kind == TEXTURE_MIX) {
      top -= 3;
      float a = stack[top + 2].x;
      v = stack[top] * (1.0f - a) + stack[top + 1] * a;
    } else { // TEXTURE_SCALE
      top -= 2;
      v = stack[top] * stack[top + 1];
    }
    if (top < 0 || top >= TEXTURE_STACK) return make_float3(0.0f, 0.0f, 0.0f); // malformed
    stack[top++] = v;
  }
  return top == 1 ? stack[0] : make_float3(0.0f, 0.0f, 0.0f);
}

// A reflectance or transmittance texture's value, clamped to [0, 1] as pbrt-v4's materials do (a
// value above 1 would create energy).
INLINE float3 texture_reflectance(GLOBAL const Texture* textures, GLOBAL const float* texels,
                                  int root, float2 uv) {
  float3 a = texture_eval(textures, texels, root, uv);
  return fmin(fmax(a, make_float3(0.0f, 0.0f, 0.0f)), make_float3(1.0f, 1.0f, 1.0f));
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

// Replaces the albedo, alpha and transmittance of `m`, the material of scene triangle `tri` hit at
// barycentrics (bu, bv), by its textures' values there (reflectances clamped to [0, 1]). Only
// textured materials call it (Material's albedo_texture, alpha_texture, transmittance_texture:
// 1 + the index of a texture's root), and only scene triangles have them.
INLINE void material_apply_textures(Material* m, GLOBAL const float2* texcoords,
                                    GLOBAL const Texture* textures, GLOBAL const float* texels,
                                    int tri, float bu, float bv) {
  float2 uv = triangle_uv(texcoords, tri, bu, bv);
  if (m->albedo_texture > 0)
    m->albedo = f4_from3(texture_reflectance(textures, texels, m->albedo_texture - 1, uv), 0.0f);
  if (m->alpha_texture > 0) {
    int root = m->alpha_texture - 1;
    m->alpha = texture_alpha(textures[root].map, texture_eval(textures, texels, root, uv).x);
  }
  if (m->transmittance_texture > 0)
    m->specular =
        f4_from3(texture_reflectance(textures, texels, m->transmittance_texture - 1, uv), 0.0f);
}

#endif // CANOPY_CL_TEXTURE_H
