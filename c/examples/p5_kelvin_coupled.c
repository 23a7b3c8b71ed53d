/* P5 (two-body impact through a Kelvin contact, docs/problems.md) through the C API, with a mass
 * coupling between the bodies: the caller gives only the target restitution e; the library
 * derives the damping 2 xi sqrt(k m*) from its own effective mass m* = 1/(B M^-1 B^T). The
 * unclipped Kelvin law realises e exactly (Anagnostopoulos 1988), so the event of the run must
 * show e, and m* must be (m1 m2 - c^2)/(m1 + m2 + 2c), coded here independently.
 * Also the settings' error exits. Returns non-zero on any failure, so ctest reports it. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "martello.h"

static int failures = 0, checks = 0;

static void expect(const char *what, int ok, double got, double want) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: got %.17g want %.17g\n", what, got, want);
  }
}

int main(void) {
  const double m1 = 1.0, m2 = 2.0, c = 0.3, k = 1e4, v0 = 1.0, e = 0.5;
  double cp[MARTELLO_NPAR_CONTACT] = {0}, mstar = 0.0, values[MARTELLO_NEVENT];
  int contact = -1, n = 0, st;
  char msg[512];
  martello_model *m = NULL;
  martello_run *r = NULL;
  martello_settings s;

  cp[MARTELLO_P_STIFF] = k;
  cp[MARTELLO_P_RESTITUTION] = e;
  martello_model_create(2, 0, 1, 0, 1, &m);
  martello_model_set_node(m, 0, m1, 0.0, v0, 0);
  martello_model_set_node(m, 1, m2, 0.0, 0.0, 0);
  martello_model_add_contact(m, 0, 1, 0.0, MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_KELVIN, cp);
  martello_model_add_mass_coupling(m, 0, 1, c);

  /* m*: a 2x2 inverse, a few roundings */
  const double want = (m1 * m2 - c * c) / (m1 + m2 + 2.0 * c);
  st = martello_model_effective_masses(m, &mstar);
  expect("effective mass with a coupling", st == MARTELLO_OK && fabs(mstar - want) <= 1e-15 * want,
         mstar, want);

  /* the registry's defaults; only the step and the span are the caller's */
  st = martello_settings_default(MARTELLO_INT_RK8PD, &s);
  expect("settings_default", st == MARTELLO_OK && s.kind == MARTELLO_INT_RK8PD && s.rtol == 1e-8,
         s.rtol, 1e-8);
  s.dt = 1e-3;
  s.t_end = 0.2;
  s.rtol = 1e-11;
  s.atol = 1e-14;
  martello_run_create(&r);
  st = martello_run_set_settings(r, &s);
  expect("set_settings", st == MARTELLO_OK, st, MARTELLO_OK);
  st = martello_dynamic_run(m, r);
  martello_run_message(r, msg, sizeof msg);
  if (st != MARTELLO_OK) printf("run: %s\n", msg);
  martello_run_events(r, &n, &contact, values);
  /* rk8pd at rtol 1e-11 locates the separation to ~1e-10: 1e-8 leaves a margin of 100 */
  const double got = -values[MARTELLO_EVENT_V_OUT] / values[MARTELLO_EVENT_V_IN];
  expect("one impact realising the target e", st == MARTELLO_OK && n == 1 && fabs(got - e) <= 1e-8,
         got, e);
  /* the onset, located to the steppers' tolerance, gives v_in to ~1e-12 */
  expect("approach speed v0", fabs(values[MARTELLO_EVENT_V_IN] - v0) <= 1e-10,
         values[MARTELLO_EVENT_V_IN], v0);
  martello_run_free(&r);

  /* error exits: a bad field is refused and named; the run keeps no settings */
  martello_run_create(&r);
  martello_settings_default(MARTELLO_INT_MOREAU_JEAN, &s);
  s.dt = 1e-3;
  s.t_end = 0.2;
  s.theta = 0.3;
  st = martello_run_set_settings(r, &s);
  martello_run_message(r, msg, sizeof msg);
  expect("theta out of range refused and named",
         st == MARTELLO_ERR_ARGUMENT && strstr(msg, "settings.theta") != NULL &&
             strstr(msg, "[0.5, 1]") != NULL, st, MARTELLO_ERR_ARGUMENT);
  expect("run without settings", martello_dynamic_run(m, r) == MARTELLO_ERR_STATE, 0, MARTELLO_ERR_STATE);
  s.theta = 0.5;
  s.dt = 0.0;
  st = martello_run_set_settings(r, &s);
  martello_run_message(r, msg, sizeof msg);
  expect("dt = 0 refused and named", st == MARTELLO_ERR_ARGUMENT && strstr(msg, "settings.dt") != NULL,
         st, MARTELLO_ERR_ARGUMENT);
  expect("unknown integrator", martello_settings_default(42, &s) == MARTELLO_ERR_ARGUMENT, 0,
         MARTELLO_ERR_ARGUMENT);
  martello_run_free(&r);
  martello_model_free(&m);

  printf("p5_kelvin_coupled: %d passed, %d failed\n", checks - failures, failures);
  return failures != 0;
}
