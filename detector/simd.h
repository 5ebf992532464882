// Which vector code the detector compiles, decided in this one place.
//
// The hot loops (run masks, run centres, list matching, visibility counts) have up to three
// forms with identical results: SSE2 intrinsics (x86-64, where SSE2 is always present), GCC
// and Clang vector extensions (any other architecture, e.g. NEON on ARM boards), and plain
// scalar loops (other compilers). Compiling with OAL_PORTABLE_SIMD defined selects the forms
// other architectures take, so that x86-64 can test them: the detector_portable_tests target
// runs the detector's tests against such a build.
#pragma once

#if defined(__SSE2__) && !defined(OAL_PORTABLE_SIMD)
#define OAL_HAVE_SSE2 1
#include <emmintrin.h>
#else
#define OAL_HAVE_SSE2 0
#endif

#if defined(__GNUC__)
#define OAL_HAVE_VECTOR_EXTENSIONS 1
#else
#define OAL_HAVE_VECTOR_EXTENSIONS 0
#endif
