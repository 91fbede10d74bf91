// HOMESH_VECTOR_CLONES: compile a hot loop's function twice, for x86-64-v3 (AVX2 and FMA: four
// doubles a vector) and for the baseline x86-64 the build targets (SSE2: two), and let the first
// call pick the one the processor runs (GCC's function multiversioning, an ifunc resolved once).
//
// Why: the optimiser's node kernels are vectorised loops over quadrature points; built for the
// baseline they use half the vector width of any x86 made since 2013. On the long cylinder
// (Part.makeCylinder(1, 1000), order 4, 873,000 nodes) a whole build for x86-64-v3 swept in
// 24.6 s where the baseline took 33.9 s; the clones keep one binary for every x86-64 machine.
//
// The two clones round differently (FMA contraction, four-lane sums): a mesh optimised on a
// machine without AVX2 agrees with one made on a machine with it to rounding, not bit for bit.
// Only the optimiser's energy kernels take it; the certified quality (quality/) is built for the
// baseline alone. Elsewhere (another compiler, another processor) it expands to nothing.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define HOMESH_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define HOMESH_VECTOR_CLONES
#endif
