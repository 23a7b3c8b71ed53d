/* STREAM-like triad a = b + s c on three arrays of n doubles (McCalpin's STREAM "Triad"),
 * the memory floor benchmarks/perf/chain_vs_opensees.py prints next to the chain step.
 * Usage: triad N REPEATS -> the best bandwidth in GB/s, counting 24 bytes per element
 * (STREAM's convention: two reads and one write, no write-allocate). */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv) {
  long n = argc > 1 ? atol(argv[1]) : 20000000L;
  int reps = argc > 2 ? atoi(argv[2]) : 10;
  double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
  if (!a || !b || !c) return 1;
  for (long i = 0; i < n; i++) { a[i] = 0.0; b[i] = 1.0; c[i] = 2.0; }
  double best = 1e300, s = 3.0;
  for (int r = 0; r < reps; r++) {
    double t0 = now();
    for (long i = 0; i < n; i++) a[i] = b[i] + s * c[i];
    double t = now() - t0;
    if (t < best) best = t;
    b[r % n] = a[(r + 1) % n];   /* keeps the loop from being hoisted */
  }
  printf("%.3f\n", 24.0 * n / best / 1e9);
  return a[n / 2] > 0 ? 0 : 2;
}
