/* P1 (mass on a rigid plane, static) through the C API, checked against the closed form of
 * docs/problems.md P1, coded here independently. Also the error exits: one bad argument at a
 * time, each must return its documented code (as LAPACK's error-exit tests do).
 * Returns non-zero on any failure, so ctest reports it. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "martello.h"

static int failures = 0, checks = 0;

static void expect_close(const char *what, double got, double want, double rtol) {
  double err = fabs(got - want);
  checks++;
  if (!(err <= rtol * fabs(want))) {
    failures++;
    printf("FAIL %s: got %.17g want %.17g (rel err %.3g > %.1g)\n", what, got, want,
           err / fabs(want), rtol);
  }
}

static void expect_status(const char *what, int got, int want) {
  checks++;
  if (got != want) {
    failures++;
    printf("FAIL %s: status %s, expected %s\n", what, martello_status_name(got),
           martello_status_name(want));
  }
}

/* Build P1: m = 1, k = 100, h = 0.05, g = 9.81, with the given scheme and ε. */
static martello_model *p1(int scheme, double eps) {
  martello_model *m = NULL;
  double lp[MARTELLO_NPAR_LINK] = {0}, cp[MARTELLO_NPAR_CONTACT] = {0};
  lp[MARTELLO_L_STIFF] = 100.0;
  cp[MARTELLO_P_STIFF] = eps;
  cp[MARTELLO_P_EXPONENT] = 1.0;
  cp[MARTELLO_P_RESTITUTION] = -1.0;
  if (martello_model_create(1, 1, 1, 0, 0, &m) != MARTELLO_OK) return NULL;
  martello_model_set_node(m, 0, 1.0, 0.0, 0.0, 0);
  martello_model_add_link(m, MARTELLO_LINK_SPRING, 0, MARTELLO_GROUND, lp);
  martello_model_add_contact(m, 0, MARTELLO_GROUND, 0.05, scheme, MARTELLO_LAW_LINEAR, cp);
  martello_model_set_gravity(m, 9.81);
  return m;
}

int main(void) {
  const double mass = 1.0, k = 100.0, h = 0.05, g = 9.81;
  double u, force, pen, cond[4];
  int active, counters[3], st;
  char msg[512];

  /* The header's enums are rows of the library's registry (tests/test_registry.py checks
   * all of them; here a few through the C API), and martello_status_name names every
   * status code as the registry's table "status" does. */
  const char *tables[] = {"laws", "links", "schemes", "time_functions", "constants",
                          "constants", "contact_parameters", "link_parameters"};
  const char *names[] = {"jankowski", "bar", "augmented-lagrange", "half_sine", "NPAR_CONTACT",
                         "NPAR_TF", "clip", "vreg"};
  const int values[] = {MARTELLO_LAW_JANKOWSKI, MARTELLO_LINK_BAR,
                        MARTELLO_SCHEME_AUGMENTED_LAGRANGE, MARTELLO_TF_HALF_SINE,
                        MARTELLO_NPAR_CONTACT, MARTELLO_NPAR_TF, MARTELLO_P_CLIP, MARTELLO_L_VREG};
  for (size_t i = 0; i < sizeof values / sizeof values[0]; i++) {
    int row = -1, rows = 0, cols = 0;
    double v[16] = {0.0};   /* a row has as many values as the table has columns */
    checks++;
    if (martello_registry_shape(tables[i], &rows, &cols) != MARTELLO_OK ||
        cols > (int)(sizeof v / sizeof v[0]) ||
        martello_registry_find(tables[i], names[i], &row) != MARTELLO_OK ||
        martello_registry_entry(tables[i], row, NULL, 0, v) != MARTELLO_OK || v[0] != values[i]) {
      failures++;
      printf("FAIL registry %s.%s: library %g, header %d\n", tables[i], names[i], v[0], values[i]);
    }
  }
  int rows = 0, cols = 0;
  martello_registry_shape("status", &rows, &cols);
  for (int i = 0; i < rows; i++) {
    char name[32];
    double v = 0.0;
    checks++;
    if (martello_registry_entry("status", i, name, (int)sizeof name, &v) != MARTELLO_OK ||
        strcmp(martello_status_name((int)v), name) != 0) {
      failures++;
      printf("FAIL status %s = %g: martello_status_name says %s\n", name, v,
             martello_status_name((int)v));
    }
  }
  checks++;
  /* the header's statuses: 0 to MARTELLO_ROOT_FOUND and -1 to MARTELLO_ERR_INTERRUPTED */
  const int n_status = MARTELLO_ROOT_FOUND + 1 - MARTELLO_ERR_INTERRUPTED;
  if (rows != n_status ||
      martello_registry_shape("no such table", &rows, &cols) != MARTELLO_ERR_ARGUMENT) {
    failures++;
    printf("FAIL registry: %d status codes (%d expected), or an unknown table accepted\n", rows,
           n_status);
  }

  /* Lagrange: u = h, P = m g − k h (docs/problems.md P1). A 2×2 KKT solve: a few ulps, 1e-14. */
  martello_model *m = p1(MARTELLO_SCHEME_LAGRANGE, 0.0);
  st = martello_static_solve(m, 1e-14, 100, &u, &force, &pen, &active, counters, cond);
  expect_status("lagrange solve", st, MARTELLO_OK);
  expect_close("lagrange u", u, h, 1e-14);
  expect_close("lagrange P", force, mass * g - k * h, 1e-14);
  /* the library's own closed form of P1 (docs/c-api.md "Closed forms"): u, lambda, force */
  {
    const double par[4] = {mass, k, h, g};
    double cf[4];
    int n_cf = 0;
    expect_status("closed form p1_static_lagrange",
                  martello_closed_form("p1_static_lagrange", par, 4, cf, &n_cf), MARTELLO_OK);
    expect_close("closed-form u against the solve", cf[0], u, 1e-14);
    expect_close("closed-form force against the solve", cf[2], force, 1e-14);
  }
  martello_model_free(&m);
  checks++;
  if (m != NULL) { failures++; printf("FAIL model_free must null the handle\n"); }

  /* Penalty ε = 1e4: u = (m g + ε h)/(k + ε); P = ε(u − h) loses log10(h/δ) ≈ 2 digits. */
  const double eps = 1e4;
  m = p1(MARTELLO_SCHEME_PENALTY, eps);
  st = martello_static_solve(m, 1e-14, 100, &u, &force, &pen, &active, counters, cond);
  expect_status("penalty solve", st, MARTELLO_OK);
  expect_close("penalty u", u, (mass * g + eps * h) / (k + eps), 1e-14);
  expect_close("penalty P", force, eps * (mass * g - k * h) / (k + eps), 1e-11);
  martello_model_free(&m);

  /* ε/k = 1e16: finishes, returns the ill-conditioning outcome and says why. */
  m = p1(MARTELLO_SCHEME_PENALTY, 1e18);
  st = martello_static_solve(m, 1e-14, 100, &u, &force, &pen, &active, counters, cond);
  expect_status("penalty 1e16 solve", st, MARTELLO_ILL_CONDITIONED);
  martello_model_message(m, msg, sizeof msg);
  checks++;
  if (strstr(msg, "digits") == NULL || !isfinite(u) || !isfinite(force) || cond[1] < 8.0) {
    failures++;
    printf("FAIL penalty 1e16: message '%s', u %g, P %g, digits lost %g\n", msg, u, force, cond[1]);
  }
  martello_model_free(&m);

  /* Error exits, one bad argument at a time. */
  double lp[MARTELLO_NPAR_LINK] = {0}, cp[MARTELLO_NPAR_CONTACT] = {0};
  expect_status("create n=0", martello_model_create(0, 0, 0, 0, 0, &m), MARTELLO_ERR_ARGUMENT);
  martello_model_create(2, 1, 1, 0, 0, &m);
  expect_status("negative mass", martello_model_set_node(m, 0, -1.0, 0, 0, 0), MARTELLO_ERR_ARGUMENT);
  expect_status("node out of range", martello_model_set_node(m, 5, 1.0, 0, 0, 0), MARTELLO_ERR_ARGUMENT);
  expect_status("NaN u0", martello_model_set_node(m, 0, 1.0, NAN, 0, 0), MARTELLO_ERR_ARGUMENT);
  expect_status("unknown link", martello_model_add_link(m, 99, 0, 1, lp), MARTELLO_ERR_ARGUMENT);
  expect_status("self link", martello_model_add_link(m, MARTELLO_LINK_SPRING, 1, 1, lp), MARTELLO_ERR_ARGUMENT);
  expect_status("unknown scheme", martello_model_add_contact(m, 0, 1, 0.0, 9, 1, cp), MARTELLO_ERR_ARGUMENT);
  expect_status("unknown law", martello_model_add_contact(m, 0, 1, 0.0, MARTELLO_SCHEME_PENALTY, 99, cp), MARTELLO_ERR_ARGUMENT);
  cp[5] = 0.5; /* the slot where an effective mass used to go: reserved now */
  expect_status("reserved slot", martello_model_add_contact(m, 0, 1, 0.0, MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR, cp), MARTELLO_ERR_ARGUMENT);
  cp[5] = 0.0;
  expect_status("solve before nodes set", martello_static_solve(m, 1e-14, 10, &u, &force, &pen, &active, counters, cond), MARTELLO_ERR_STATE);
  expect_status("null model", martello_model_set_gravity(NULL, 1.0), MARTELLO_ERR_ARGUMENT);
  martello_model_free(&m);

  printf("p1_static: %d passed, %d failed\n", checks - failures, failures);
  return failures != 0;
}
