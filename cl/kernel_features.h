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
#define HAS_PRIM_SPHERE 1
#endif

#endif // CANOPY_CL_FEATURES_H
