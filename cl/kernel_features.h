// Compile-time features (named kernel_features.h: a bare features.h would shadow glibc's). The host
// derives them from the scene (host/render/features.cpp) and passes them as -D options, so a kernel
// contains only the code a scene uses. Without CANOPY_FEATURES_SET (the host reference, C++ tests)
// everything is on; the kernels then make the same decisions.
#ifndef CANOPY_CL_FEATURES_H
#define CANOPY_CL_FEATURES_H

#ifndef CANOPY_FEATURES_SET
#define HAS_LIGHT_POINT 1
#define HAS_LIGHT_SPOT 1
#define HAS_LIGHT_SPHERE 1
#define HAS_LIGHT_QUAD 1
#define HAS_LIGHT_TRIANGLE 1
#define HAS_LIGHT_DISK 1
#define HAS_LIGHT_DISTANT 1
#define HAS_LIGHT_ENVIRONMENT 1
#define HAS_PRIM_SPHERE 1
#define HAS_PRIM_DISK 1
#define HAS_MATERIAL_CONDUCTOR 1
#define HAS_MATERIAL_PLASTIC 1
#define HAS_MATERIAL_DIELECTRIC 1
#define HAS_MATERIAL_COATED 1
#define HAS_MATERIAL_MIX 1
#define HAS_MATERIAL_DIFFUSE_TRANSMISSION 1
#define HAS_MEDIUM 1
#define HAS_TEXTURES 1
#endif

// MIS between light and BSDF sampling (RendererOptions::mis; off only for the ablation).
#ifndef CANOPY_MIS
#define CANOPY_MIS 1
#endif

// `x` has type T and the kernel has feature T: folds to 0 when the feature is off. (A ternary:
// `HAS_T && ...` inside || draws clang's -Wconstant-logical-operand in the kernel build.)
#define IS_LIGHT(l, T) (HAS_##T ? (l)->type == T : 0)
#define IS_PRIM(p, T) (HAS_##T ? (p)->type == T : 0)
#define IS_MATERIAL(m, T) (HAS_##T ? (m)->type == T : 0)
// A reflective material with a glossy lobe: where BRDF-oriented light sampling may apply (the
// BRDF stages exist only for scenes with one, cl/integrator/brdf_mis.h).
#define HAS_MICROFACET (HAS_MATERIAL_CONDUCTOR || HAS_MATERIAL_PLASTIC || HAS_MATERIAL_COATED)
// GGX code (cl/bsdf/microfacet.h): the glossy materials and rough glass.
#define HAS_GGX (HAS_MICROFACET || HAS_MATERIAL_DIELECTRIC)
// One feature for glass and thin sheets (cl/bsdf/dielectric.h), one for both coated materials
// (cl/bsdf/layered.h).
#define HAS_MATERIAL_THIN_DIELECTRIC HAS_MATERIAL_DIELECTRIC
#define HAS_MATERIAL_COATED_DIFFUSE HAS_MATERIAL_COATED
#define HAS_MATERIAL_COATED_CONDUCTOR HAS_MATERIAL_COATED
// Dielectric Fresnel (cl/bsdf/fresnel.h): the glossy materials and glass.
#define HAS_FRESNEL HAS_GGX
// Lights at infinity (cl/types.h): distant or environment lights.
#define HAS_INFINITE_LIGHT (HAS_LIGHT_DISTANT || HAS_LIGHT_ENVIRONMENT)

#endif // CANOPY_CL_FEATURES_H
