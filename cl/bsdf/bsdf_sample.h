// The result of sampling a BSDF (cl/bsdf/bsdf.h), shared by every BSDF.
#ifndef CANOPY_CL_BSDF_SAMPLE_H
#define CANOPY_CL_BSDF_SAMPLE_H

#include "../compat.h"

// Local shading frame: z = shading normal, wo.z > 0.
typedef struct BsdfSample {
  float3 wi;     // sampled direction (unit)
  float3 weight; // f |wi.z| / pdf; a delta lobe: its reflectance / its choice probability;
                 // 0: absorbed or invalid (wi below the horizon, degenerate input)
  float pdf;     // bsdf_pdf(wo, wi) of the non-delta lobes (0 for a delta sample)
  int is_delta;  // wi was chosen by a delta lobe (perfect mirror)
} BsdfSample;

INLINE BsdfSample bsdf_sample_absorbed(float3 wi) {
  BsdfSample s;
  s.wi = wi;
  s.weight = make_float3(0.0f, 0.0f, 0.0f);
  s.pdf = 0.0f;
  s.is_delta = 0;
  return s;
}

// The mirror direction of wo about the normal.
INLINE float3 reflect_z(float3 wo) {
  return make_float3(-wo.x, -wo.y, wo.z);
}

#endif // CANOPY_CL_BSDF_SAMPLE_H
