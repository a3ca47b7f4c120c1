// The vectorised FLIP kernels for baseline x86-64 (SSE2): every 64-bit x86 CPU runs them.
#define IBLCHECK_KERNELS_FUNCTION sse2_kernels
#define IBLCHECK_KERNELS_NAME "sse2"
#include "metrics/flip/kernels_vector.inc"
