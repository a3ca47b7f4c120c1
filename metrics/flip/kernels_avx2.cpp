// The vectorised FLIP kernels compiled with -mavx2 (and without -mfma: see flip/kernels.h). Called
// only when the CPU has AVX2 (flip/kernels_select.cpp).
#ifndef __AVX2__
#error "kernels_avx2.cpp must be compiled with -mavx2"
#endif
#ifdef __FMA__
#error "kernels_avx2.cpp must not be compiled with FMA: results would differ from the other variants"
#endif
#define IBLCHECK_KERNELS_FUNCTION avx2_kernels
#define IBLCHECK_KERNELS_NAME "avx2"
#include "metrics/flip/kernels_vector.inc"
