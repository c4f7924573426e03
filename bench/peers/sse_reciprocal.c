/* This CPU's SSE approximations _mm_rsqrt_ps and _mm_rcp_ps, for make_sse_tables.py.
 * Build: gcc -O2 -shared -fPIC -o /tmp/libsse_reciprocal.so bench/peers/sse_reciprocal.c */
#include <xmmintrin.h>

void sse_rsqrt(const float* x, float* y, long n) {
  for (long i = 0; i + 4 <= n; i += 4) _mm_storeu_ps(y + i, _mm_rsqrt_ps(_mm_loadu_ps(x + i)));
}

void sse_rcp(const float* x, float* y, long n) {
  for (long i = 0; i + 4 <= n; i += 4) _mm_storeu_ps(y + i, _mm_rcp_ps(_mm_loadu_ps(x + i)));
}
