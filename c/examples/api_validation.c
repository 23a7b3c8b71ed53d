/* The C API checks every parameter when an item is added (docs/c-api.md, "Parameter
 * domains"): one bad value at a time, each door must return MARTELLO_ERR_ARGUMENT with a
 * message naming what is wrong, and accept the same item with the value in its domain (as
 * LAPACK's error-exit tests do, one argument at a time). A caller other than the Python front
 * end gets the error when it builds the model, not a run that fails later. Returns non-zero
 * on any failure, so ctest reports it. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "martello.h"

static int failures = 0, checks = 0;

/* A model of 3 free nodes with room for what one test adds. */
static martello_model *model(void) {
  martello_model *m = NULL;
  int i;
  if (martello_model_create(3, 4, 4, 2, 2, &m) != MARTELLO_OK) return NULL;
  for (i = 0; i < 3; i++) martello_model_set_node(m, i, 1.0, 0.0, 0.0, 0);
  return m;
}

/* status st of `what` must be want; for an error, the model's message must contain `says`. */
static void expect(const char *what, martello_model *m, int st, int want, const char *says) {
  char msg[512] = "";
  checks++;
  if (m) martello_model_message(m, msg, sizeof msg);
  if (st != want || (want != MARTELLO_OK && says && !strstr(msg, says))) {
    failures++;
    printf("FAIL %s: status %s (expected %s), message '%s' (expected to hold '%s')\n", what,
           martello_status_name(st), martello_status_name(want), msg, says ? says : "");
  }
}

/* One link of `kind` with slot `slot` set to bad, then to good; the other slots valid. */
static void link_case(const char *what, int kind, int slot, double bad, double good,
                      const char *says) {
  double p[MARTELLO_NPAR_LINK] = {0};
  martello_model *m = model();
  p[MARTELLO_L_STIFF] = 100.0;
  p[MARTELLO_L_DAMP] = 2.0;
  p[MARTELLO_L_YIELD] = 5.0;
  p[MARTELLO_L_HARDENING] = 0.1;
  p[MARTELLO_L_ALPHA] = 0.5;
  p[MARTELLO_L_VREG] = 1e-6;
  p[slot] = bad;
  expect(what, m, martello_model_add_link(m, kind, 0, MARTELLO_GROUND, p), MARTELLO_ERR_ARGUMENT,
         says);
  p[slot] = good;
  expect(what, m, martello_model_add_link(m, kind, 0, MARTELLO_GROUND, p), MARTELLO_OK, NULL);
  martello_model_free(&m);
}

/* One contact (scheme, law) with slot `slot` set to bad, then to good. */
static void contact_case(const char *what, int scheme, int law, int slot, double bad,
                         double good, const char *says) {
  double p[MARTELLO_NPAR_CONTACT] = {0};
  martello_model *m = model();
  p[MARTELLO_P_STIFF] = 1e6;
  p[MARTELLO_P_EXPONENT] = 1.5;
  p[MARTELLO_P_RESTITUTION] = scheme == MARTELLO_SCHEME_RESTITUTION ? 0.8 : -1.0;
  p[slot] = bad;
  expect(what, m, martello_model_add_contact(m, 0, 1, 0.01, scheme, law, p),
         MARTELLO_ERR_ARGUMENT, says);
  p[slot] = good;
  expect(what, m, martello_model_add_contact(m, 0, 1, 0.01, scheme, law, p), MARTELLO_OK, NULL);
  martello_model_free(&m);
}

/* One time function of `kind` with par[slot] set to bad, then to good. */
static void function_case(const char *what, int kind, int slot, double bad, double good,
                          const char *says) {
  double p[MARTELLO_NPAR_TF] = {1.0, 10.0, 0.0, 0.0, 1.0};
  martello_model *m = model();
  p[slot] = bad;
  expect(what, m, martello_model_add_nodal_force(m, 0, kind, p, 0, NULL, NULL),
         MARTELLO_ERR_ARGUMENT, says);
  expect(what, m, martello_model_set_ground_acceleration(m, kind, p, 0, NULL, NULL),
         MARTELLO_ERR_ARGUMENT, says);
  p[slot] = good;
  expect(what, m, martello_model_add_nodal_force(m, 0, kind, p, 0, NULL, NULL), MARTELLO_OK, NULL);
  martello_model_free(&m);
}

int main(void) {
  const double nan = NAN, inf = INFINITY;
  martello_model *m = NULL;
  double lp[MARTELLO_NPAR_LINK] = {100.0}, cp[MARTELLO_NPAR_CONTACT] = {1e6, 1.5, 0.0, -1.0};
  double tf[MARTELLO_NPAR_TF] = {1.0, 0.0, 0.0, 0.0, 0.0}, t2[2] = {0.0, 1.0}, y2[2] = {0.0, 1.0};
  double t_down[2] = {1.0, 0.0}, k2[4] = {2.0, -1.0, -1.0, 2.0}, asym[4] = {2.0, -1.0, -0.5, 2.0};
  double k_chain[3] = {100.0, 100.0, 100.0}, gaps[2] = {0.01, 0.01}, c_bad[3] = {1.0, -1.0, 1.0};
  int two[2] = {0, 1}, same[2] = {1, 1}, kinds[2] = {MARTELLO_LINK_SPRING, MARTELLO_LINK_SPRING};
  int ground[2] = {MARTELLO_GROUND, MARTELLO_GROUND};
  int row_nodes[3] = {0, 1, 2};
  double row_coef[3] = {1.0, -0.5, -0.5};
  double links2[2 * MARTELLO_NPAR_LINK] = {100.0, 0, 0, 0, 0, 0, -100.0, 0, 0, 0, 0, 0};

  /* model_create and set_node */
  expect("model_create: n_nodes 0", NULL, martello_model_create(0, 1, 1, 0, 0, &m),
         MARTELLO_ERR_ARGUMENT, NULL);
  expect("model_create: max_links -1", NULL, martello_model_create(2, -1, 1, 0, 0, &m),
         MARTELLO_ERR_ARGUMENT, NULL);
  m = model();
  expect("set_node: node 3 of 3", m, martello_model_set_node(m, 3, 1.0, 0, 0, 0),
         MARTELLO_ERR_ARGUMENT, "node index out of range");
  expect("set_node: free, mass 0", m, martello_model_set_node(m, 0, 0.0, 0, 0, 0),
         MARTELLO_ERR_ARGUMENT, "mass must be > 0 for a free node");
  expect("set_node: fixed, mass -1", m, martello_model_set_node(m, 0, -1.0, 0, 0, 1),
         MARTELLO_ERR_ARGUMENT, ">= 0 for a fixed one");
  expect("set_node: fixed, mass 0", m, martello_model_set_node(m, 0, 0.0, 0, 0, 1), MARTELLO_OK,
         NULL);
  expect("set_node: u0 NaN", m, martello_model_set_node(m, 0, 1.0, nan, 0, 0),
         MARTELLO_ERR_ARGUMENT, "must be finite");
  expect("set_node: v0 inf", m, martello_model_set_node(m, 0, 1.0, 0, inf, 0),
         MARTELLO_ERR_ARGUMENT, "must be finite");
  martello_model_free(&m);

  /* links: every slot each kind reads */
  link_case("spring k = 0", MARTELLO_LINK_SPRING, MARTELLO_L_STIFF, 0.0, 1.0,
            "add_link: spring: par[MARTELLO_L_STIFF] (k) = 0.00000E+00 must be > 0");
  link_case("spring k = -1e300", MARTELLO_LINK_SPRING, MARTELLO_L_STIFF, -1e300, 1e300,
            "(k) = -1.00000E+300 must be > 0");
  link_case("spring k NaN", MARTELLO_LINK_SPRING, MARTELLO_L_STIFF, nan, 1.0, "must be finite");
  link_case("dashpot c = 0", MARTELLO_LINK_DASHPOT, MARTELLO_L_DAMP, 0.0, 1e-3,
            "dashpot: par[MARTELLO_L_DAMP] (c)");
  link_case("bilinear k = -1", MARTELLO_LINK_BILINEAR, MARTELLO_L_STIFF, -1.0, 1.0,
            "bilinear: par[MARTELLO_L_STIFF] (k)");
  link_case("bilinear F_y = 0", MARTELLO_LINK_BILINEAR, MARTELLO_L_YIELD, 0.0, 1.0,
            "bilinear: par[MARTELLO_L_YIELD] (F_y) = 0.00000E+00 must be > 0");
  link_case("bilinear hardening = 1", MARTELLO_LINK_BILINEAR, MARTELLO_L_HARDENING, 1.0, 0.0,
            "par[MARTELLO_L_HARDENING] (hardening) = 1.00000E+00 must be in [0, 1)");
  link_case("bilinear hardening < 0", MARTELLO_LINK_BILINEAR, MARTELLO_L_HARDENING, -0.1, 0.99,
            "must be in [0, 1)");
  link_case("fluid damper c = 0", MARTELLO_LINK_FLUID_DAMPER, MARTELLO_L_DAMP, 0.0, 1.0,
            "fluid_damper: par[MARTELLO_L_DAMP] (c)");
  link_case("fluid damper alpha = 0", MARTELLO_LINK_FLUID_DAMPER, MARTELLO_L_ALPHA, 0.0, 2.0,
            "par[MARTELLO_L_ALPHA] (alpha) = 0.00000E+00 must be in (0, 2]");
  link_case("fluid damper alpha > 2", MARTELLO_LINK_FLUID_DAMPER, MARTELLO_L_ALPHA, 2.5, 1.0,
            "must be in (0, 2]");
  link_case("fluid damper v_reg < 0", MARTELLO_LINK_FLUID_DAMPER, MARTELLO_L_VREG, -1e-6, 0.0,
            "par[MARTELLO_L_VREG] (v_reg) = -1.00000E-06 must be >= 0");
  link_case("bar EA/L = 0", MARTELLO_LINK_BAR, MARTELLO_L_STIFF, 0.0, 2e7,
            "bar: par[MARTELLO_L_STIFF] (EA/L)");
  /* a slot a kind does not read is not checked (beyond being finite) */
  link_case("spring ignores its yield slot", MARTELLO_LINK_SPRING, MARTELLO_L_YIELD, nan, -5.0,
            "must be finite");
  m = model();
  expect("link: unknown kind", m, martello_model_add_link(m, 99, 0, MARTELLO_GROUND, lp),
         MARTELLO_ERR_ARGUMENT, "unknown link kind");
  expect("link: a == b", m, martello_model_add_link(m, MARTELLO_LINK_SPRING, 1, 1, lp),
         MARTELLO_ERR_ARGUMENT, "same node");
  expect("link: node out of range", m, martello_model_add_link(m, MARTELLO_LINK_SPRING, 0, 7, lp),
         MARTELLO_ERR_ARGUMENT, "out of range");
  expect("bulk links: entry 1 bad", m, martello_model_add_links(m, 2, kinds, two, ground, links2),
         MARTELLO_ERR_ARGUMENT, "entry 1: add_link: spring: par[MARTELLO_L_STIFF]");
  martello_model_free(&m);

  /* contacts: every slot each scheme and law reads */
  contact_case("penalty stiffness = 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR,
               MARTELLO_P_STIFF, 0.0, 1e3, "penalty: par[MARTELLO_P_STIFF] (stiffness)");
  /* the case: a Hertz contact whose exponent a zero-initialised block left 0 */
  contact_case("hertz exponent = 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_HERTZ,
               MARTELLO_P_EXPONENT, 0.0, 1.5,
               "add_contact: penalty: par[MARTELLO_P_EXPONENT] (n (1.5: Hertz)) = 0.00000E+00 "
               "must be > 0");
  contact_case("hunt-crossley exponent < 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_HUNT_CROSSLEY,
               MARTELLO_P_EXPONENT, -1.0, 1.0, "par[MARTELLO_P_EXPONENT]");
  contact_case("flores exponent = 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_FLORES,
               MARTELLO_P_EXPONENT, 0.0, 1.5, "par[MARTELLO_P_EXPONENT]");
  contact_case("gonthier exponent = 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_GONTHIER,
               MARTELLO_P_EXPONENT, 0.0, 1.5, "par[MARTELLO_P_EXPONENT]");
  contact_case("lankarani-nikravesh exponent = 0", MARTELLO_SCHEME_PENALTY,
               MARTELLO_LAW_LANKARANI_NIKRAVESH, MARTELLO_P_EXPONENT, 0.0, 1.5,
               "par[MARTELLO_P_EXPONENT]");
  /* a law with a fixed exponent does not read the slot: 0 is accepted */
  contact_case("linear ignores its exponent", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR,
               MARTELLO_P_EXPONENT, inf, 0.0, "must be finite");
  contact_case("kelvin damping < 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_KELVIN,
               MARTELLO_P_DAMPING, -1.0, 0.0, "par[MARTELLO_P_DAMPING] (damping) = -1.00000E+00 "
               "must be >= 0");
  contact_case("jankowski xi < 0", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_JANKOWSKI,
               MARTELLO_P_DAMPING, -0.1, 0.1, "par[MARTELLO_P_DAMPING]");
  contact_case("penalty restitution > 1", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_HUNT_CROSSLEY,
               MARTELLO_P_RESTITUTION, 1.5, 0.7, "par[MARTELLO_P_RESTITUTION] (e (-1: none))");
  contact_case("penalty restitution -0.5", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR,
               MARTELLO_P_RESTITUTION, -0.5, -1.0, "must be in [0, 1]");
  contact_case("clip with the linear law", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR,
               MARTELLO_P_CLIP, 1.0, 0.0, "par[MARTELLO_P_CLIP] = 1.00000E+00 must be 0, or 1 "
               "for the kelvin law");
  contact_case("clip 0.7 with kelvin", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_KELVIN,
               MARTELLO_P_CLIP, 0.7, 1.0, "par[MARTELLO_P_CLIP]");
  contact_case("reserved slot 5", MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_LINEAR, 5, 1.0, 0.0,
               "reserved");
  contact_case("augmented-lagrange stiffness = 0", MARTELLO_SCHEME_AUGMENTED_LAGRANGE, 0,
               MARTELLO_P_STIFF, 0.0, 1e6, "augmented-lagrange: par[MARTELLO_P_STIFF]");
  contact_case("restitution contact without e", MARTELLO_SCHEME_RESTITUTION, 0,
               MARTELLO_P_RESTITUTION, -1.0, 0.0, "contact: par[MARTELLO_P_RESTITUTION]");
  contact_case("restitution contact e > 1", MARTELLO_SCHEME_RESTITUTION, 0,
               MARTELLO_P_RESTITUTION, 1.01, 1.0, "must be in [0, 1]");
  contact_case("lagrange restitution > 1", MARTELLO_SCHEME_LAGRANGE, 0, MARTELLO_P_RESTITUTION,
               2.0, 0.5, "par[MARTELLO_P_RESTITUTION]");
  m = model();
  expect("contact: unknown scheme", m, martello_model_add_contact(m, 0, 1, 0.0, 9, 1, cp),
         MARTELLO_ERR_ARGUMENT, "unknown scheme");
  expect("contact: unknown law", m,
         martello_model_add_contact(m, 0, 1, 0.0, MARTELLO_SCHEME_PENALTY, 42, cp),
         MARTELLO_ERR_ARGUMENT, "unknown contact law");
  expect("contact: gap inf", m,
         martello_model_add_contact(m, 0, 1, inf, MARTELLO_SCHEME_PENALTY, 1, cp),
         MARTELLO_ERR_ARGUMENT, "must be finite");
  expect("contact: a == b", m,
         martello_model_add_contact(m, 2, 2, 0.0, MARTELLO_SCHEME_PENALTY, 1, cp),
         MARTELLO_ERR_ARGUMENT, "same node");
  martello_model_free(&m);

  /* rows (a contact or link on a combination of DOFs): the same parameter domains as the
   * pair doors, checked by the same code */
  m = model();
  cp[MARTELLO_P_EXPONENT] = 0.0;
  expect("contact row: hertz exponent 0", m,
         martello_model_add_contact_row(m, 3, row_nodes, row_coef, 0.01, MARTELLO_SCHEME_PENALTY,
                                        MARTELLO_LAW_HERTZ, cp),
         MARTELLO_ERR_ARGUMENT, "penalty: par[MARTELLO_P_EXPONENT]");
  cp[MARTELLO_P_EXPONENT] = 1.5;
  expect("contact row: valid hertz", m,
         martello_model_add_contact_row(m, 3, row_nodes, row_coef, 0.01, MARTELLO_SCHEME_PENALTY,
                                        MARTELLO_LAW_HERTZ, cp), MARTELLO_OK, NULL);
  cp[MARTELLO_P_RESTITUTION] = 1.5;
  expect("contact row: restitution e 1.5", m,
         martello_model_add_contact_row(m, 3, row_nodes, row_coef, 0.01,
                                        MARTELLO_SCHEME_RESTITUTION, 0, cp),
         MARTELLO_ERR_ARGUMENT, "par[MARTELLO_P_RESTITUTION]");
  cp[MARTELLO_P_RESTITUTION] = -1.0;
  lp[MARTELLO_L_STIFF] = 0.0;
  expect("link row: spring k 0", m,
         martello_model_add_link_row(m, MARTELLO_LINK_SPRING, 3, row_nodes, row_coef, lp),
         MARTELLO_ERR_ARGUMENT, "spring: par[MARTELLO_L_STIFF]");
  lp[MARTELLO_L_STIFF] = 100.0;
  lp[MARTELLO_L_DAMP] = 1.0;
  lp[MARTELLO_L_ALPHA] = 3.0;
  expect("link row: fluid damper alpha 3", m,
         martello_model_add_link_row(m, MARTELLO_LINK_FLUID_DAMPER, 3, row_nodes, row_coef, lp),
         MARTELLO_ERR_ARGUMENT, "par[MARTELLO_L_ALPHA]");
  lp[MARTELLO_L_ALPHA] = 0.5;
  expect("link row: valid fluid damper", m,
         martello_model_add_link_row(m, MARTELLO_LINK_FLUID_DAMPER, 3, row_nodes, row_coef, lp),
         MARTELLO_OK, NULL);
  martello_model_free(&m);

  /* chains: each link and contact as the doors check it, named by its entry */
  m = model();
  expect("chain: n = 0", m, martello_model_add_chain(m, 0, 0, k_chain, NULL, NULL, NULL, NULL,
                                                     0, 0, cp), MARTELLO_ERR_ARGUMENT, "n >= 1");
  expect("chain: fy without hardening", m,
         martello_model_add_chain(m, 0, 3, k_chain, NULL, k_chain, NULL, NULL, 0, 0, cp),
         MARTELLO_ERR_ARGUMENT, "give both fy and hardening");
  expect("chain: dashpot c < 0", m,
         martello_model_add_chain(m, 0, 3, k_chain, c_bad, NULL, NULL, NULL, 0, 0, cp),
         MARTELLO_ERR_ARGUMENT, "chain entry 1: add_chain: dashpot c");
  cp[MARTELLO_P_EXPONENT] = 0.0;
  expect("chain: hertz contacts with exponent 0", m,
         martello_model_add_chain(m, 0, 3, k_chain, NULL, NULL, NULL, gaps,
                                  MARTELLO_SCHEME_PENALTY, MARTELLO_LAW_HERTZ, cp),
         MARTELLO_ERR_ARGUMENT, "chain entry 0: add_contact: penalty: par[MARTELLO_P_EXPONENT]");
  cp[MARTELLO_P_EXPONENT] = 1.5;
  k_chain[2] = 0.0;
  expect("chain: a spring k = 0", m,
         martello_model_add_chain(m, 0, 3, k_chain, NULL, NULL, NULL, NULL, 0, 0, cp),
         MARTELLO_ERR_ARGUMENT, "chain entry 2: add_link: spring: par[MARTELLO_L_STIFF]");
  k_chain[2] = 100.0;
  expect("chain: valid", m, martello_model_add_chain(m, 0, 3, k_chain, NULL, NULL, NULL, gaps,
                                                     MARTELLO_SCHEME_PENALTY,
                                                     MARTELLO_LAW_HERTZ, cp), MARTELLO_OK, NULL);
  martello_model_free(&m);

  /* time functions */
  function_case("sine omega = 0", MARTELLO_TF_SINE, 1, 0.0, 3.0,
                "time function: sine: par[1] (omega) = 0.00000E+00 must be > 0");
  function_case("sine t_end = t_start", MARTELLO_TF_SINE, 4, 0.0, 2.0, "must be later than");
  function_case("half sine over no time", MARTELLO_TF_HALF_SINE, 4, 0.0, 0.1,
                "par[4] = t_end = 0.00000E+00 must be later than par[3] = t_start");
  function_case("rectangular ending first", MARTELLO_TF_RECTANGULAR, 3, 2.0, 0.5,
                "must be later than");
  function_case("constant NaN", MARTELLO_TF_CONSTANT, 0, nan, -3.0, "must be finite");
  m = model();
  expect("function: unknown kind", m, martello_model_add_nodal_force(m, 0, 77, tf, 0, NULL, NULL),
         MARTELLO_ERR_ARGUMENT, "unknown kind");
  expect("force: node out of range", m,
         martello_model_add_nodal_force(m, 5, MARTELLO_TF_CONSTANT, tf, 0, NULL, NULL),
         MARTELLO_ERR_ARGUMENT, "node out of range");
  expect("table: one sample", m,
         martello_model_add_nodal_force(m, 0, MARTELLO_TF_TABLE, tf, 1, t2, y2),
         MARTELLO_ERR_ARGUMENT, ">= 2 (t, y) pairs");
  expect("table: times going back", m,
         martello_model_add_nodal_force(m, 0, MARTELLO_TF_TABLE, tf, 2, t_down, y2),
         MARTELLO_ERR_ARGUMENT, "increase strictly");
  expect("table: valid", m, martello_model_add_nodal_force(m, 0, MARTELLO_TF_TABLE, tf, 2, t2, y2),
         MARTELLO_OK, NULL);
  martello_model_free(&m);

  /* mass couplings, stiffness blocks, gravity */
  m = model();
  expect("coupling: a == b", m, martello_model_add_mass_coupling(m, 1, 1, 0.1),
         MARTELLO_ERR_ARGUMENT, "two distinct nodes");
  expect("coupling: NaN", m, martello_model_add_mass_coupling(m, 0, 1, nan),
         MARTELLO_ERR_ARGUMENT, "finite value");
  expect("block: asymmetric k", m, martello_model_add_stiffness_block(m, 2, two, asym, NULL),
         MARTELLO_ERR_ARGUMENT, "symmetric");
  expect("block: a node twice", m, martello_model_add_stiffness_block(m, 2, same, k2, NULL),
         MARTELLO_ERR_ARGUMENT, "appears twice");
  k2[0] = 0.0;
  expect("block: diagonal 0", m, martello_model_add_stiffness_block(m, 2, two, k2, NULL),
         MARTELLO_ERR_ARGUMENT, "diagonal of k must be > 0");
  k2[0] = 2.0;
  expect("block: valid", m, martello_model_add_stiffness_block(m, 2, two, k2, NULL), MARTELLO_OK,
         NULL);
  expect("gravity: NaN", m, martello_model_set_gravity(m, nan), MARTELLO_ERR_ARGUMENT, NULL);
  martello_model_free(&m);

  printf("%d checks, %d failures\n", checks, failures);
  return failures != 0;
}
