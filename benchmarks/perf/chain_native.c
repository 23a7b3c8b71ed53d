/* The benchmark chain of benchmarks/perf/chain_vs_opensees.py built and run through the C API
 * alone (docs/performance.md "The library alone"): no Python, so the time and the memory are
 * the library's. The model is the scene's [[chain]]: node b_i with a spring and a dashpot to
 * ground (links numbered spring, dashpot of b_1, of b_2 ...), contact b_i-b_{i+1}; held per
 * node by martello_model_add_chain, or with --items as links and contacts by the bulk doors
 * (docs/c-api.md "Chains", "Building a large model").
 *
 *     chain_native N STEPS [--items] [--full-phases] [--track WHAT]
 *
 * prints one JSON line: the wall and CPU seconds of martello_dynamic_run (its set-up included), the
 * resident memory (VmRSS) before the model, after it is built and after the run, the peak
 * (VmHWM), the counters, a checksum of the peaks (to compare two builds or the two doors) and
 * u of the first and last node at the end.
 * --full-phases asks for every contact's phase list (martello_run_set_phase_lists); --track
 * keeps only WHAT, a comma-separated list of node_peaks, link_peaks, contact_peaks, phases,
 * all, or none (martello_run_set_tracking; default all). */
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "martello.h"

static const double M = 1.0, K1 = 100.0, K2 = 400.0, ZETA = 0.05, GAP = 0.01, EPS = 1.0e5,
                    AMP = 3.0, OMEGA = 8.0, DT = 1.0e-3;

/* a field of /proc/self/status in bytes (VmRSS, VmHWM) */
static double proc_status(const char *key) {
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  double kb = -1.0;
  size_t len = strlen(key);
  if (!f) return -1.0;
  while (fgets(line, sizeof line, f))
    if (strncmp(line, key, len) == 0 && line[len] == ':') kb = atof(line + len + 1);
  fclose(f);
  return kb * 1024.0;
}

static void check(int st, const char *what, martello_model *m, martello_run *r) {
  char msg[512] = "";
  if (st >= 0) return;
  if (r) martello_run_message(r, msg, sizeof msg);
  else if (m) martello_model_message(m, msg, sizeof msg);
  fprintf(stderr, "chain_native: %s failed (%d): %s\n", what, st, msg);
  exit(1);
}

static double clock_s(clockid_t id) {
  struct timespec ts;
  clock_gettime(id, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
static double now(void) { return clock_s(CLOCK_MONOTONIC); }
/* the process' CPU seconds: on a shared machine the time it ran, not the time it waited */
static double cpu_now(void) { return clock_s(CLOCK_PROCESS_CPUTIME_ID); }

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: chain_native N STEPS [--items] [--full-phases] [--track WHAT]\n");
    return 2;
  }
  int n = atoi(argv[1]), steps = atoi(argv[2]);
  int full = 0, items = 0, track = MARTELLO_TRACK_ALL;
  for (int a = 3; a < argc; ++a) {
    if (strcmp(argv[a], "--full-phases") == 0) full = 1;
    else if (strcmp(argv[a], "--items") == 0) items = 1;
    else if (strcmp(argv[a], "--track") == 0 && a + 1 < argc) {
      /* a comma-separated list of the library's names (table "tracking"), or none */
      static const char *names[] = {"node_peaks", "link_peaks", "contact_peaks", "phases", "all"};
      static const int flags[] = {MARTELLO_TRACK_NODE_PEAKS, MARTELLO_TRACK_LINK_PEAKS,
                                  MARTELLO_TRACK_CONTACT_PEAKS, MARTELLO_TRACK_PHASES,
                                  MARTELLO_TRACK_ALL};
      char list[256];
      snprintf(list, sizeof list, "%s", argv[++a]);
      track = 0;
      for (char *w = strtok(list, ","); w; w = strtok(NULL, ",")) {
        int k = 0;
        while (k < 5 && strcmp(w, names[k]) != 0) ++k;
        if (k == 5 && strcmp(w, "none") != 0) {
          fprintf(stderr, "chain_native: --track: unknown name %s (use node_peaks, link_peaks, "
                          "contact_peaks, phases, all or none)\n", w);
          return 2;
        }
        if (k < 5) track |= flags[k];
      }
    } else {
      fprintf(stderr, "chain_native: unknown option %s\n", argv[a]);
      return 2;
    }
  }
  /* every block of 64 kB or more its own mapping, returned when freed: the resident memory
   * is then what is allocated (glibc's adaptive threshold would keep this driver's freed
   * input arrays resident and count them as the library's) */
  mallopt(M_MMAP_THRESHOLD, 64 * 1024);
  double rss0 = proc_status("VmRSS");
  martello_model *m = NULL;
  check(martello_model_create(n, items ? 2 * n : 0, items ? n - 1 : 0, 0, 0, &m), "model_create",
        NULL, NULL);
  {
    double *mass = malloc(n * sizeof *mass), *zero = calloc(n, sizeof *zero);
    int *fixed = calloc(n, sizeof *fixed);
    for (int i = 0; i < n; ++i) mass[i] = M;
    check(martello_model_set_nodes(m, n, mass, zero, zero, fixed), "set_nodes", m, NULL);
    free(mass); free(zero); free(fixed);
  }
  if (!items) {
    double *k = malloc(n * sizeof *k), *c = malloc(n * sizeof *c), *gap = malloc(n * sizeof *gap);
    double par[MARTELLO_NPAR_CONTACT] = {0};
    for (int i = 0; i < n; ++i) {
      k[i] = i % 2 == 0 ? K1 : K2;
      c[i] = 2.0 * ZETA * sqrt(k[i] * M);
      gap[i] = GAP;
    }
    par[MARTELLO_P_STIFF] = EPS; par[MARTELLO_P_EXPONENT] = 1.0; par[MARTELLO_P_RESTITUTION] = -1.0;
    check(martello_model_add_chain(m, 0, n, k, c, NULL, NULL, gap, MARTELLO_SCHEME_PENALTY,
                                   MARTELLO_LAW_LINEAR, par), "add_chain", m, NULL);
    free(k); free(c); free(gap);
  } else {
    int *kind = malloc(2 * n * sizeof *kind), *a = malloc(2 * n * sizeof *a),
        *b = malloc(2 * n * sizeof *b);
    double *par = calloc((size_t)2 * n * MARTELLO_NPAR_LINK, sizeof *par);
    for (int i = 0; i < n; ++i) {
      double k = i % 2 == 0 ? K1 : K2;
      kind[2 * i] = MARTELLO_LINK_SPRING; kind[2 * i + 1] = MARTELLO_LINK_DASHPOT;
      a[2 * i] = a[2 * i + 1] = i; b[2 * i] = b[2 * i + 1] = -1;
      par[(size_t)2 * i * MARTELLO_NPAR_LINK + MARTELLO_L_STIFF] = k;
      /* zeta of a node-to-ground oscillator: c = 2 zeta sqrt(k m), as the scene loader */
      par[(size_t)(2 * i + 1) * MARTELLO_NPAR_LINK + MARTELLO_L_DAMP] = 2.0 * ZETA * sqrt(k * M);
    }
    check(martello_model_add_links(m, 2 * n, kind, a, b, par), "add_links", m, NULL);
    free(kind); free(a); free(b); free(par);
  }
  if (items && n > 1) {
    int nc = n - 1;
    int *a = malloc(nc * sizeof *a), *b = malloc(nc * sizeof *b), *scheme = malloc(nc * sizeof *scheme),
        *law = malloc(nc * sizeof *law);
    double *gap = malloc(nc * sizeof *gap), *par = calloc((size_t)nc * MARTELLO_NPAR_CONTACT, sizeof *par);
    for (int i = 0; i < nc; ++i) {
      a[i] = i; b[i] = i + 1; gap[i] = GAP;
      scheme[i] = MARTELLO_SCHEME_PENALTY; law[i] = MARTELLO_LAW_LINEAR;
      double *p = par + (size_t)i * MARTELLO_NPAR_CONTACT;
      p[MARTELLO_P_STIFF] = EPS; p[MARTELLO_P_EXPONENT] = 1.0; p[MARTELLO_P_RESTITUTION] = -1.0;
    }
    check(martello_model_add_contacts(m, nc, a, b, gap, scheme, law, par), "add_contacts", m, NULL);
    free(a); free(b); free(scheme); free(law); free(gap); free(par);
  }
  {
    double tf[MARTELLO_NPAR_TF] = {AMP, OMEGA, 0.0, 0.0, 1e300};
    check(martello_model_set_ground_acceleration(m, MARTELLO_TF_SINE, tf, 0, NULL, NULL),
          "ground_acceleration", m, NULL);
  }
  double rss_model = proc_status("VmRSS");

  martello_run *r = NULL;
  martello_settings s;
  check(martello_run_create(&r), "run_create", NULL, NULL);
  check(martello_settings_default(MARTELLO_INT_NEWMARK, &s), "settings", NULL, r);
  s.dt = DT; s.t_end = steps * DT; s.every = steps < 1000 ? steps : 1000;
  s.beta = 0.25; s.gamma = 0.5;
  check(martello_run_set_settings(r, &s), "set_settings", NULL, r);
  int out_nodes[2] = {0, n - 1};
  check(martello_run_set_outputs(r, 2, out_nodes, 0, NULL), "set_outputs", NULL, r);
  if (full) check(martello_run_set_phase_lists(r, -1), "set_phase_lists", NULL, r);
  check(martello_run_set_tracking(r, track), "set_tracking", NULL, r);
  double t0 = now(), c0 = cpu_now();
  check(martello_dynamic_run(m, r), "dynamic_run", NULL, r);
  double wall = now() - t0, cpu = cpu_now() - c0;
  double rss_run = proc_status("VmRSS"), hwm = proc_status("VmHWM");

  long long cnt[MARTELLO_NCOUNTERS];
  martello_run_counters(r, cnt);
  int nev = 0;
  martello_run_events(r, &nev, NULL, NULL);
  double *u_max = malloc(n * sizeof(double)), *u_min = malloc(n * sizeof(double));
  double *v = malloc(n * sizeof(double)), *acc = malloc(n * sizeof(double)),
         *upk = malloc(n * sizeof(double)), *tpk = malloc(n * sizeof(double));
  double *pen = malloc(n * sizeof(double)), *force_max = malloc(n * sizeof(double));
  int *imp = malloc(n * sizeof(int));
  martello_run_peaks(r, u_max, u_min, v, acc, pen, force_max, imp, upk, tpk);
  double checksum = 0.0;
  long long impacts = 0;
  for (int i = 0; i < n; ++i) checksum += fmax(u_max[i], -u_min[i]);
  for (int i = 0; i < n - 1; ++i) impacts += imp[i];
  char sum[40];
  if (checksum != checksum) snprintf(sum, sizeof sum, "null");   /* node peaks not tracked */
  else snprintf(sum, sizeof sum, "%.17g", checksum);
  /* u of the first and last node at the end: the history's last row (t, u of the two output
   * nodes, ...); a lean kernel of the same chain (lean_chain.f90) prints the same numbers */
  int rows = 0, cols = 0;
  check(martello_run_history_shape(r, &rows, &cols), "history_shape", NULL, r);
  double *hist = malloc((size_t)rows * cols * sizeof *hist);
  check(martello_run_history(r, hist), "history", NULL, r);
  double u_first = hist[(size_t)(rows - 1) * cols + 1], u_last = hist[(size_t)(rows - 1) * cols + 2];
  free(hist);
  printf("{\"n\": %d, \"steps\": %lld, \"wall_s\": %.6f, \"cpu_s\": %.6f, \"ns_per_dof_step\": %.3f, "
         "\"rss_start\": %.0f, \"rss_model\": %.0f, \"rss_run\": %.0f, \"rss_peak\": %.0f, "
         "\"model_B_per_dof\": %.1f, \"peak_B_per_dof\": %.1f, \"newton\": %lld, "
         "\"factorizations\": %lld, \"fused\": %lld, \"events\": %d, \"impacts\": %lld, "
         "\"sum_absmax_u\": %s, \"tracking\": %d, \"u_first\": %.17g, \"u_last\": %.17g}\n",
         n, cnt[MARTELLO_COUNTER_STEPS], wall, cpu, wall / ((double)n * steps) * 1e9, rss0, rss_model,
         rss_run, hwm, (rss_model - rss0) / n, (hwm - rss0) / n,
         cnt[MARTELLO_COUNTER_NEWTON_ITERATIONS], cnt[MARTELLO_COUNTER_FACTORIZATIONS],
         cnt[MARTELLO_COUNTER_FUSED_CHAIN_STEPS], nev, impacts, sum, track, u_first, u_last);
  free(u_max); free(u_min); free(v); free(acc); free(upk); free(tpk); free(pen); free(force_max); free(imp);
  martello_run_free(&r);
  martello_model_free(&m);
  return 0;
}
