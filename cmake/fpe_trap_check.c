/* The checks of a MARTELLO_FPE_TRAP build (scripts/fpe-trap), with the traps of
 * fpe_trap_on.c: `fpe_trap_check` runs P2 of docs/problems.md (a mass on a spring bouncing on
 * a plane under gravity) on every integrator, with a penalty plane and, where it runs, a
 * restitution one, and expects each run to finish OK: any invalid operation, division by
 * zero or overflow in the library stops it with SIGFPE. `fpe_trap_check 0` divides by zero
 * on purpose: its test expects that SIGFPE (the traps are on). */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#include "martello.h"

static void trapped(int sig) {
  (void)sig;
  static const char ok[] = "ok: 1/0 trapped (SIGFPE)\n";
  (void)!write(1, ok, sizeof ok - 1);
  _exit(0);
}

static int run_p2(int integrator, int scheme) {
  double lp[MARTELLO_NPAR_LINK] = {0}, cp[MARTELLO_NPAR_CONTACT] = {0};
  martello_model *m = NULL;
  martello_run *r = NULL;
  martello_settings s;
  char msg[512];
  lp[MARTELLO_L_STIFF] = 100.0;
  cp[MARTELLO_P_STIFF] = 1e6;
  cp[MARTELLO_P_RESTITUTION] = scheme == MARTELLO_SCHEME_RESTITUTION ? 0.8 : -1.0;
  martello_model_create(1, 1, 1, 0, 0, &m);
  martello_model_set_node(m, 0, 1.0, 0.0, 0.0, 0);
  martello_model_add_link(m, MARTELLO_LINK_SPRING, 0, -1, lp);
  martello_model_add_contact(m, 0, -1, 0.05, scheme, MARTELLO_LAW_LINEAR, cp);
  martello_model_set_gravity(m, 9.81);
  martello_settings_default(integrator, &s);
  s.dt = 1e-4;
  s.t_end = 0.5;
  s.every = 100;
  martello_run_create(&r);
  int st = martello_run_set_settings(r, &s);
  if (st == MARTELLO_OK) st = martello_dynamic_run(m, r);
  martello_run_message(r, msg, sizeof msg);
  printf("%s integrator %d scheme %d: %s %s\n", st == MARTELLO_OK ? "ok  " : "FAIL", integrator,
         scheme, martello_status_name(st), msg);
  martello_run_free(&r);
  martello_model_free(&m);
  return st == MARTELLO_OK ? 0 : 1;
}

int main(int argc, char **argv) {
  if (argc > 1) {
    volatile double zero = atof(argv[1]);
    signal(SIGFPE, trapped);
    printf("%g\n", 1.0 / zero);      /* SIGFPE here when the traps are on */
    printf("FAIL: 1/0 did not trap\n");
    return 1;
  }
  const int penalty[] = {MARTELLO_INT_NEWMARK, MARTELLO_INT_HHT, MARTELLO_INT_GENERALIZED_ALPHA,
                         MARTELLO_INT_CENTRAL_DIFFERENCE, MARTELLO_INT_MOREAU_JEAN,
                         MARTELLO_INT_RKF45, MARTELLO_INT_RK8PD, MARTELLO_INT_MSBDF, MARTELLO_INT_IDA};
  const int rigid[] = {MARTELLO_INT_MOREAU_JEAN, MARTELLO_INT_NEWMARK_LAGRANGE, MARTELLO_INT_RKF45,
                       MARTELLO_INT_RK8PD, MARTELLO_INT_MSBDF, MARTELLO_INT_IDA};
  int failures = 0;
  for (size_t i = 0; i < sizeof penalty / sizeof *penalty; i++)
    failures += run_p2(penalty[i], MARTELLO_SCHEME_PENALTY);
  for (size_t i = 0; i < sizeof rigid / sizeof *rigid; i++)
    failures += run_p2(rigid[i], MARTELLO_SCHEME_RESTITUTION);
  printf("fpe_trap_check: %d failed\n", failures);
  return failures != 0;
}
