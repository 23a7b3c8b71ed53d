/* The first-order ODE of a scene on SUNDIALS CVODE (BDF, Adams) and ARKODE (explicit,
 * diagonally implicit and ImEx Runge-Kutta tables); docs/sundials-ode.md.
 *
 * State y, node by node: [u_i, v_i] (interleaved, so that a chain's Jacobian is a narrow
 * band), y' = f(t, y) = [v; M^-1 (f_ext(t) - f_int(u, v))] from the kernels' evaluator, penalty
 * contacts inside f_int, fixed nodes at rest. The ImEx tables split f = f_E + f_I with the
 * loads explicit, f_E = [0; M^-1 f_ext(t)] (no Jacobian, kinks at the stops), and the internal
 * forces implicit, f_I = [v; -M^-1 f_int]. The Newton systems of BDF, Adams and the implicit
 * stages use the library's analytic Jacobian [[0, I], [-M^-1 K_t, -M^-1 C_t]] of the laws'
 * branches held (martello_eval_tangent), banded for a lumped mass (half-bandwidth 2 kd + 1 in
 * the interleaved layout: 3 for a chain), dense with SUNDIALS' difference quotients where a
 * mass coupling makes M^-1 full.
 *
 * Rigid contacts (lagrange, restitution) closed by the accumulation rule are bilateral
 * constraints on the accelerations, as on GSL (c/event_driven.c): a <- a + M^-1 B_H^T lambda with
 * W_H lambda = -B_H a, so that B_H v and B_H u stay as the restart left them (on the constraints)
 * to the Newton tolerance; the state is projected onto them at every restart. Their Jacobian is
 * SUNDIALS' difference quotients of that projected right-hand side (banded: the projection's
 * couplings inside the band).
 *
 * Events are those of every SUNDIALS integrator here (c/ode_events.c, as on IDA): roots
 * (CVodeRootInit / ARKStepRootInit) of the gaps, their rates, the multipliers of closed rigid
 * contacts and the laws' switches; impacts by Newton's law on all touching rigid contacts at
 * once, the accumulation rule of c/accumulation.c. At an event the state is made consistent,
 * committed on the new branches, and the integrator restarts there (CVodeReInit; ARKStepReset,
 * which keeps the last step as the first: a one-step method has no history to rebuild).
 * The kinks of the loads and t_end are the only stop times (properties of the scene): both step
 * past the output times, a history row inside a step is its state on the step's interpolant
 * (CVodeGetDky, ARKStepGetDky), so the steps, and every result, do not depend on the output
 * interval (docs/sundials-ode.md, output rows). While a rigid contact is held, which may hold
 * its nodes still, the steps are bounded by the loads' time scale so that its multiplier cannot
 * change sign twice unseen inside one (oe_max_step; docs/sundials-ode.md, held contacts).
 * Steps are taken one at a time
 * (CV_ONE_STEP, ARK_ONE_STEP); every accepted state is a sample of the run's observer, with the
 * works, the node extrema and the located peaks of the step on the interpolant (c/ode_events.c). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "martello.h"
#include "martello_internal.h"
#include "ode_events.h"
#include "sundials_ode.h"

/* Kinds of the table "methods" (fortran/registry.f90 METHOD_*). */
enum { KIND_BDF = 1, KIND_ADAMS = 2, KIND_ERK = 3, KIND_DIRK = 4, KIND_IMEX = 5 };
/* ARKODE's default table here: Dormand-Prince 5(4), the method value 108 (ERK id 8). */
#define ARK_DEFAULT_METHOD 108
#define MAX_STEPS 100000000L
/* error-test failures of one step before the integrator gives up (SUNDIALS' default: 7) */
#define MAX_ERR_TEST_FAILS 50


#define fail(P, ...) oe_fail(&(P)->E, __VA_ARGS__)

/* ---- the two SUNDIALS integrators behind one set of calls ---------------------------------- */

static int be_dky(ode_problem *P, double t, int k, N_Vector out) {
  return P->ark ? ARKStepGetDky(P->mem, t, k, out) : CVodeGetDky(P->mem, t, k, out);
}

static const char *be_flag(ode_problem *P, int flag) {
  return P->ark ? ARKStepGetReturnFlagName(flag) : CVodeGetReturnFlagName(flag);
}

static int be_stop(ode_problem *P, double t) {
  return P->ark ? ARKStepSetStopTime(P->mem, t) : CVodeSetStopTime(P->mem, t);
}

/* The longest step now (oe_max_step; 0: no limit, SUNDIALS' own default). */
static int be_max_step(ode_problem *P) {
  const double h = oe_max_step(&P->E);
  int flag = P->ark ? ARKStepSetMaxStep(P->mem, h) : CVodeSetMaxStep(P->mem, h);
  if (flag < 0) return fail(P, MARTELLO_ERR_EXTERNAL, "%s: SetMaxStep failed: %s", P->name, be_flag(P, flag));
  return MARTELLO_OK;
}

static double be_last_step(ode_problem *P) {
  double h = 0.0;
  if ((P->ark ? ARKStepGetLastStep(P->mem, &h) : CVodeGetLastStep(P->mem, &h)) < 0) h = 0.0;
  return h;
}

/* The counters now, in the order of MARTELLO_COUNTER_* (events and chatter left 0). */
static int be_counts(ode_problem *P, long c[9]) {
  long cf = 0, nfi = 0, nre_ls = 0;
  int st = 0;
  memset(c, 0, 9 * sizeof c[0]);
  if (P->ark) {
    st |= ARKStepGetNumSteps(P->mem, &c[MARTELLO_COUNTER_STEPS]);
    st |= ARKStepGetNumErrTestFails(P->mem, &c[MARTELLO_COUNTER_REJECTED_STEPS]);
    st |= ARKStepGetNumRhsEvals(P->mem, &c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS], &nfi);
    /* without root functions ARKODE keeps no root memory and refuses the query (ARK_MEM_NULL,
     * unlike CVODE): no roots, no root evaluations -- e.g. a cluster of local stepping whose
     * contacts all lie between clusters (docs/sundials-ode.md, local stepping) */
    if (oe_nroots(&P->E) > 0) st |= ARKStepGetNumGEvals(P->mem, &c[MARTELLO_COUNTER_ROOT_EVALUATIONS]);
    /* ImEx: a step evaluates both parts at a stage; count the stage evaluations once */
    if (P->kind == KIND_DIRK) c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS] = nfi;
    c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS] += P->row_rhs;
    if (P->kind != KIND_ERK) {
      st |= ARKStepGetNumNonlinSolvConvFails(P->mem, &cf);
      st |= ARKStepGetNumNonlinSolvIters(P->mem, &c[MARTELLO_COUNTER_NEWTON_ITERATIONS]);
      st |= ARKStepGetNumLinRhsEvals(P->mem, &nre_ls);
      st |= ARKStepGetNumLinSolvSetups(P->mem, &c[MARTELLO_COUNTER_FACTORIZATIONS]);
      st |= ARKStepGetNumJacEvals(P->mem, &c[MARTELLO_COUNTER_JACOBIAN_EVALUATIONS]);
    }
  } else {
    st |= CVodeGetNumSteps(P->mem, &c[MARTELLO_COUNTER_STEPS]);
    st |= CVodeGetNumErrTestFails(P->mem, &c[MARTELLO_COUNTER_REJECTED_STEPS]);
    st |= CVodeGetNumRhsEvals(P->mem, &c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS]);
    st |= CVodeGetNumGEvals(P->mem, &c[MARTELLO_COUNTER_ROOT_EVALUATIONS]);
    st |= CVodeGetNumNonlinSolvConvFails(P->mem, &cf);
    st |= CVodeGetNumNonlinSolvIters(P->mem, &c[MARTELLO_COUNTER_NEWTON_ITERATIONS]);
    st |= CVodeGetNumLinRhsEvals(P->mem, &nre_ls);
    st |= CVodeGetNumLinSolvSetups(P->mem, &c[MARTELLO_COUNTER_FACTORIZATIONS]);
    st |= CVodeGetNumJacEvals(P->mem, &c[MARTELLO_COUNTER_JACOBIAN_EVALUATIONS]);
  }
  c[MARTELLO_COUNTER_REJECTED_STEPS] += cf;
  c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS] += nre_ls;
  return st;
}

/* Add the counters since the last call to the run. A restart may set SUNDIALS' counters back
 * to 0 (CVodeReInit) or not (ARKStepReset): the baseline is read again after it (rebase). */
static int flush_counts(ode_problem *P) {
  long c[9];
  if (be_counts(P, c) != 0) return fail(P, MARTELLO_ERR_EXTERNAL, "%s: could not read the counters", P->name);
  return oe_add_counts(&P->E, c);
}

static void rebase_counts(ode_problem *P) {
  if (be_counts(P, P->E.cnt_last) != 0) memset(P->E.cnt_last, 0, sizeof P->E.cnt_last);
}

/* ---- right-hand sides, Jacobian, roots ------------------------------------------------------ */

static int finite_or_flag(ode_problem *P, const double *f) {
  for (sunindextype k = 0; k < P->N; k++)
    if (!isfinite(f[k])) {
      P->E.nan_seen = 1;
      return 1; /* recoverable: the integrator retries with a smaller step, then gives up */
    }
  return 0;
}

/* f = [v; M^-1 (f_ext - f_int)], with the forces of the closed rigid contacts */
static int rhs_full(realtype t, N_Vector yy, N_Vector ff, void *data) {
  ode_problem *P = data;
  ode_events *E = &P->E;
  const double *y = N_VGetArrayPointer(yy);
  double *f = N_VGetArrayPointer(ff);
  oe_gather(E, y, E->u, E->v);
  if (martello_eval_acceleration(E->ev, t, E->u, E->v, E->a) != MARTELLO_OK) return -1;
  if (oe_constrain(E, E->a) != MARTELLO_OK) return -1;
  for (int i = 0; i < E->n; i++) {
    f[2 * i] = E->fixed[i] ? 0.0 : E->v[i];
    f[2 * i + 1] = E->a[i];
  }
  return finite_or_flag(P, f);
}

/* ImEx: the loads alone, f_E = [0; M^-1 f_ext(t)], and the internal forces, f_I = [v; -M^-1 f_int]
 * (each constrained: the closed set's projection is linear). */
static int rhs_split(realtype t, N_Vector yy, N_Vector ff, ode_problem *P, int loads) {
  ode_events *E = &P->E;
  const double *y = N_VGetArrayPointer(yy);
  double *f = N_VGetArrayPointer(ff);
  oe_gather(E, y, E->u, E->v);
  if (martello_eval_forces(E->ev, t, E->u, E->v, E->fint, E->fext) != MARTELLO_OK) return -1;
  for (int i = 0; i < E->n; i++) E->a[i] = loads ? E->fext[i] : -E->fint[i];
  if (martello_eval_solve_mass(E->ev, E->a) != MARTELLO_OK) return -1;
  if (oe_constrain(E, E->a) != MARTELLO_OK) return -1;
  for (int i = 0; i < E->n; i++) {
    f[2 * i] = loads || E->fixed[i] ? 0.0 : E->v[i];
    f[2 * i + 1] = E->a[i];
  }
  return finite_or_flag(P, f);
}

static int rhs_loads(realtype t, N_Vector yy, N_Vector ff, void *data) {
  return rhs_split(t, yy, ff, data, 1);
}

static int rhs_internal(realtype t, N_Vector yy, N_Vector ff, void *data) {
  return rhs_split(t, yy, ff, data, 0);
}

/* The analytic Jacobian of f (of f_I for ImEx: f_E depends on t alone), band or dense (a
 * scene too small for a band to pay), in the interleaved layout: d u_i'/d v_i = 1, d v_i'/d u_k = -K_t(i,k)/m_i, d v_i'/d v_k = -C_t(i,k)/m_i over
 * |i - k| <= kd, on the laws' branches held (martello_eval_tangent); fixed rows and columns
 * are 0 (the evaluator holds fixed nodes at u0 and at rest). */
static int jacobian(realtype t, N_Vector yy, N_Vector fy, SUNMatrix J, void *data, N_Vector t1,
                    N_Vector t2, N_Vector t3) {
  ode_problem *P = data;
  ode_events *E = &P->E;
  const int kd = P->kd, ld = 3 * kd + 1;
  (void)t; (void)fy; (void)t1; (void)t2; (void)t3;
  oe_gather(E, N_VGetArrayPointer(yy), E->u, E->v);
  if (martello_eval_tangent(E->ev, E->u, E->v, P->kb, P->cb) != MARTELLO_OK) return -1;
  const int band = SUNMatGetID(J) == SUNMATRIX_BAND;
#define JAC(r, c) (*(band ? &SM_ELEMENT_B(J, (r), (c)) : &SM_ELEMENT_D(J, (r), (c))))
  SUNMatZero(J);
  for (int i = 0; i < E->n; i++) {
    if (E->fixed[i]) continue;
    JAC(2 * i, 2 * i + 1) = 1.0;
    const double rm = 1.0 / E->mass[i];
    const int k0 = i - kd > 0 ? i - kd : 0, k1 = i + kd < E->n - 1 ? i + kd : E->n - 1;
    for (int k = k0; k <= k1; k++) {
      if (E->fixed[k]) continue;
      const size_t at = (size_t)(2 * kd + i - k) + (size_t)k * (size_t)ld;
      JAC(2 * i + 1, 2 * k) = -P->kb[at] * rm;
      JAC(2 * i + 1, 2 * k + 1) = -P->cb[at] * rm;
    }
  }
#undef JAC
  return 0;
}

/* The roots of c/ode_events.c on the state y. */
static int roots(realtype t, N_Vector yy, realtype *g, void *data) {
  ode_problem *P = data;
  ode_events *E = &P->E;
  oe_gather(E, N_VGetArrayPointer(yy), E->uq, E->vq);
  return oe_roots(E, t, E->uq, E->vq, g);
}

static void error_handler(int code, const char *module, const char *function, char *msg,
                          void *data) {
  ode_problem *P = data;
  (void)module;
  if (code < 0) snprintf(P->msg, sizeof P->msg, "%s: %s", function, msg);
}

/* The interpolant of the last step (CVodeGetDky, ARKStepGetDky), for c/ode_events.c. */
static int interpolant(void *ctx, double t, int k, N_Vector out) {
  ode_problem *P = ctx;
  int flag = be_dky(P, t, k, out);
  if (flag < 0)
    return fail(P, MARTELLO_ERR_EXTERNAL, "%s: the interpolant failed at t = %.9e s: %s", P->name, t,
                be_flag(P, flag));
  return MARTELLO_OK;
}

/* The degree of the interpolant: the order CVODE used in its last step (its Nordsieck array's,
 * which CVodeGetDky differentiates up to; the order of the next step is set only when it
 * starts); ARKODE's Hermite interpolant of the highest degree it has (set at its creation),
 * whose derivatives past its degree are 0. */
static int degree(void *ctx) {
  ode_problem *P = ctx;
  int q = 1;
  if (P->ark) return ARK_INTERP_MAX_DEGREE;
  if (CVodeGetLastOrder(P->mem, &q) != CV_SUCCESS || q < 1) return 1;
  return q;
}

/* ---- what the observer is handed ------------------------------------------------------------- */

/* An accepted, committed state at t as a sample (a from the right-hand side there, with the
 * forces of the closed rigid contacts, which are their multipliers); k: its output grid point
 * or -1; row: an output row on the interpolant inside a step (martello_observer_row: recorded,
 * but neither a step nor a point of the energy balance's maximum, which must not move with the
 * output). */
static int observe(ode_problem *P, double t, const double *y, int k, int row) {
  ode_events *E = &P->E;
  oe_gather(E, y, E->u, E->v);
  int st = oe_closed_multipliers(E, t, E->u, E->v);
  if (st != MARTELLO_OK) return fail(P, st, "%s: acceleration failed at t = %.9e s", P->name, t);
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    E->force[j] = r >= 0 && E->closed[r] ? E->lr[r] : 0.0;
  }
  return (row ? martello_observer_row : martello_observer_sample)(E->obs, E->ev, t, E->u, E->v,
                                                                  E->ar, E->force, k);
}

static int row_by_step(ode_problem *P, double t, N_Vector out);
static int rows_setup(ode_problem *P, N_Vector y);

/* An output row inside a step (c/ode_events.c oe_rows_inside): y, the state on the interpolant,
 * or where the table's order exceeds the interpolant's degree, its own step (row_by_step). */
static int sample(void *ctx, double t, const double *y, int k) {
  ode_problem *P = ctx;
  if (P->rows_by_step) {
    int st = row_by_step(P, t, P->y_row);
    if (st != MARTELLO_OK) return st;
    y = N_VGetArrayPointer(P->y_row);
  }
  return observe(P, t, y, k, 1);
}

/* The state at a restart made consistent (c/ode_events.c), into y. */
static int prepare_restart(ode_problem *P, double t, double *y) {
  ode_events *E = &P->E;
  oe_gather(E, y, E->u, E->v);
  int st = oe_prepare_restart(E, t, E->u, E->v);
  for (int i = 0; i < E->n; i++) {
    y[2 * i] = E->u[i];
    y[2 * i + 1] = E->v[i];
  }
  return st;
}

/* A reported root exactly 0 at the return (c/ode_events.c), here also the multiplier of a
 * closed rigid contact, as the roots last evaluated it. */
static int root_stays_zero(ode_problem *P, const double *y, const int *found) {
  ode_events *E = &P->E;
  for (int r = 0; r < E->nr; r++)
    if (E->closed[r] && found[2 * E->rig_con[r]] && E->lr[r] + E->lamtol[r] == 0.0) return 1;
  return oe_root_stays_zero(E, y, found);
}

/* ---- set-up ------------------------------------------------------------------------------------- */

static void release(ode_problem *P) {
  free(P->kb);
  free(P->cb);
  oe_release(&P->E);
}

/* The method of the settings: its kind and ARKODE tables (the table "methods"). */
static int choose_method(ode_problem *P, int method) {
  P->erk_id = ARKODE_ERK_NONE;
  P->dirk_id = ARKODE_DIRK_NONE;
  if (!P->ark) {
    P->kind = method == 2 ? KIND_ADAMS : KIND_BDF;
    return MARTELLO_OK;
  }
  if (method == 0) method = ARK_DEFAULT_METHOD;
  /* ImEx pairs: the ERK and DIRK halves of one additive table */
  static const int imex[5][2] = {{ARKODE_ARK324L2SA_ERK_4_2_3, ARKODE_ARK324L2SA_DIRK_4_2_3},
                                 {ARKODE_ARK436L2SA_ERK_6_3_4, ARKODE_ARK436L2SA_DIRK_6_3_4},
                                 {ARKODE_ARK437L2SA_ERK_7_3_4, ARKODE_ARK437L2SA_DIRK_7_3_4},
                                 {ARKODE_ARK548L2SA_ERK_8_4_5, ARKODE_ARK548L2SA_DIRK_8_4_5},
                                 {ARKODE_ARK548L2SAb_ERK_8_4_5, ARKODE_ARK548L2SAb_DIRK_8_4_5}};
  if (method >= 100 && method < 200) {
    P->kind = KIND_ERK;
    P->erk_id = method - 100;
  } else if (method >= 200 && method < 300) {
    P->kind = KIND_DIRK;
    P->dirk_id = method - 100;
  } else if (method >= 300 && method < 305) {
    P->kind = KIND_IMEX;
    P->erk_id = imex[method - 300][0];
    P->dirk_id = imex[method - 300][1];
  } else {
    return fail(P, MARTELLO_ERR_ARGUMENT, "arkode: method %d is no ARKODE table (the table methods)", method);
  }
  return MARTELLO_OK;
}

static int setup(ode_problem *P, martello_model *model, martello_run *run) {
  ode_events *E = &P->E;
  int st;
  double failed = 0.0;
  martello_settings s;
  if ((st = martello_run_settings(run, &s)) != MARTELLO_OK) return st;
  P->ark = s.kind == MARTELLO_INT_ARKODE;
  P->name = P->ark ? "ARKODE" : "CVODE";
  E->name = P->name;
  E->dky = interpolant;
  E->sample = sample;
  E->ctx = P;
  if ((st = choose_method(P, s.method)) != MARTELLO_OK) return st;
  if ((st = oe_setup(E, model, run, P->name)) != MARTELLO_OK) return st;
  /* CVODE restarts its BDF or Adams history at order 1; ARKODE's one-step tables lose
   * nothing at a restart (the accumulation rule's resolution, docs/impulse.md §4) */
  E->restarts = !P->ark;
  E->degree = degree;
  /* both step past the output times (docs/sundials-ode.md, output rows); while a rigid contact
   * is held its steps are bounded by the loads' time scale instead (oe_max_step) */
  /* CVODE steps across the laws whose force is continuous at their switches, their events
   * located inside the steps; ARKODE only across those whose force's rate is bounded there too
   * (linear): an explicit table's error estimate does not bound a step across the onset of a
   * delta^(3/2) law, whose second derivative is unbounded (docs/sundials-ode.md, events inside
   * the steps) */
  st = oe_use_smooth_laws(E, P->ark ? MARTELLO_ACROSS_RATE_BOUNDED : MARTELLO_ACROSS_CONTINUOUS);
  if (st != MARTELLO_OK) return st;
  P->N = 2 * (sunindextype)E->n;
  for (int i = 0; i < E->n; i++) {
    E->iu[i] = 2 * (sunindextype)i;
    E->iv[i] = 2 * (sunindextype)i + 1;
  }
  if ((st = martello_eval_bandwidth(E->ev, &P->kd, &P->lumped)) != MARTELLO_OK)
    return fail(P, st, "%s: could not read the evaluator", P->name);
  const size_t nb = (size_t)(3 * P->kd + 1) * (size_t)E->n;
  P->kb = oe_take(nb, sizeof(double), &failed);
  P->cb = oe_take(nb, sizeof(double), &failed);
  if (failed > 0.0) return oe_fail_memory(E, "an array of the ODE state", failed);
  return MARTELLO_OK;
}

static int check(ode_problem *P, int flag, const char *call) {
  if (flag >= 0) return MARTELLO_OK;
  return fail(P, MARTELLO_ERR_EXTERNAL, "%s failed: %s", call, be_flag(P, flag));
}

/* ARKODE at (t0, y) with the run's table, tolerances and Newton test, into *memp (P->mem, or the
 * memory of the rows' own steps); on failure *memp is freed. */
static int ark_create(ode_problem *P, SUNContext ctx, double t0, N_Vector y, void **memp) {
  ARKRhsFn fe = P->kind == KIND_ERK ? rhs_full : P->kind == KIND_IMEX ? rhs_loads : NULL;
  ARKRhsFn fi = P->kind == KIND_DIRK ? rhs_full : P->kind == KIND_IMEX ? rhs_internal : NULL;
  const int implicit = P->kind != KIND_ERK;
  void *mem = *memp = ARKStepCreate(fe, fi, t0, y, ctx);
  if (!mem) return oe_fail_memory(&P->E, "the ARKODE solver memory (ARKStepCreate)", -1.0);
  int st;
  if ((st = check(P, ARKStepSetErrHandlerFn(mem, error_handler, P), "ARKStepSetErrHandlerFn")) ||
      (st = check(P, ARKStepSetTableNum(mem, P->dirk_id, P->erk_id), "ARKStepSetTableNum")) ||
      (st = check(P, ARKStepSStolerances(mem, P->E.rtol, P->E.atol), "ARKStepSStolerances")) ||
      (st = check(P, ARKStepSetUserData(mem, P), "ARKStepSetUserData")) ||
      (st = check(P, ARKStepSetMaxNumSteps(mem, -1), "ARKStepSetMaxNumSteps")) ||
      /* a law whose force has an unbounded derivative at first touch (Jankowski's damping goes
       * as delta^(1/4)) fails the error test of the first steps in contact many times over before
       * the step is small enough: ARKODE's default of 7 failures stopped P2, P5 and P7's
       * Jankowski scenes at onset (h ~ 1e-8 s) */
      (st = check(P, ARKStepSetMaxErrTestFails(mem, MAX_ERR_TEST_FAILS), "ARKStepSetMaxErrTestFails")) ||
      /* the interpolant of the steps, for the roots, the works and the located peaks: the
       * highest degree ARKODE has (5) */
      (st = check(P, ARKStepSetInterpolantDegree(mem, ARK_INTERP_MAX_DEGREE), "ARKStepSetInterpolantDegree")))
    goto out;
  if (implicit &&
      ((st = check(P, ARKStepSetDeduceImplicitRhs(mem, SUNTRUE), "ARKStepSetDeduceImplicitRhs")) ||
       /* ARKODE's Newton test accepts an iterate when min(1, crate) |correction| <= the
        * tolerance, and keeps the rate estimate crate from stage to stage until the next
        * linear-solver setup, shrinking it by crdown (0.3) at least every iteration
        * (arkStep_NlsConvTest; its own comment says crate = 1 at the first iteration). A law
        * linear between events converges in one iteration, so crate soon allows first
        * corrections many times the tolerance; after a change of step the matrix's gamma is up to
        * 20 % old, the accepted first iterate is off by up to 20 % of its correction, and the
        * embedded error estimate, built from the same stages, cannot see it (docs/sundials-ode.md,
        * the implicit tables). crdown = 1 keeps crate >= 1: an iterate is accepted only when its
        * correction is within the tolerance. */
       (st = check(P, ARKStepSetNonlinCRDown(mem, 1.0), "ARKStepSetNonlinCRDown"))))
    goto out;
  return MARTELLO_OK;
out:
  ARKStepFree(memp);
  return st;
}

/* The linear solver of the Newton systems of mem (CVODE's or ARKODE's): the analytic Jacobian
 * with a lumped mass, banded where the band is narrower than half the state (c/ida.c's rule);
 * SUNDIALS' dense difference quotients where a mass coupling makes M^-1 full, and its
 * difference quotients where rigid contacts may close (the projection of their forces is in
 * the right-hand side). */
static int linear_solver(ode_problem *P, void *mem, SUNContext ctx, N_Vector y, SUNMatrix *Jp,
                         SUNLinearSolver *LSp) {
  int st;
  const sunindextype bw = 2 * (sunindextype)P->kd + 1;
  const int band = P->lumped && 2 * bw + 1 < P->N / 2;
  const int analytic = P->lumped && P->E.nr == 0;
  *Jp = band ? SUNBandMatrix(P->N, bw, bw, ctx) : SUNDenseMatrix(P->N, P->N, ctx);
  if (!*Jp) return oe_fail_memory(&P->E, "the Jacobian matrix", -1.0);
  *LSp = band ? SUNLinSol_Band(y, *Jp, ctx) : SUNLinSol_Dense(y, *Jp, ctx);
  if (!*LSp) return oe_fail_memory(&P->E, "the linear solver", -1.0);
  if (P->ark) {
    if ((st = check(P, ARKStepSetLinearSolver(mem, *LSp, *Jp), "ARKStepSetLinearSolver"))) return st;
    if (analytic && (st = check(P, ARKStepSetJacFn(mem, jacobian), "ARKStepSetJacFn"))) return st;
  } else {
    if ((st = check(P, CVodeSetLinearSolver(mem, *LSp, *Jp), "CVodeSetLinearSolver"))) return st;
    if (analytic && (st = check(P, CVodeSetJacFn(mem, jacobian), "CVodeSetJacFn"))) return st;
  }
  return MARTELLO_OK;
}

/* Create the integrator at (0, y): method, tolerances, the linear solver of its Newton
 * systems (none for an explicit table), roots. */
static int create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *Jp, SUNLinearSolver *LSp) {
  int st;
  const int implicit = P->kind != KIND_ERK;
  if (P->ark) {
    if ((st = ark_create(P, ctx, 0.0, y, &P->mem))) return st;
  } else {
    P->mem = CVodeCreate(P->kind == KIND_ADAMS ? CV_ADAMS : CV_BDF, ctx);
    if (!P->mem) return oe_fail_memory(&P->E, "the CVODE solver memory (CVodeCreate)", -1.0);
    if ((st = check(P, CVodeSetErrHandlerFn(P->mem, error_handler, P), "CVodeSetErrHandlerFn"))) return st;
    if ((st = check(P, CVodeInit(P->mem, rhs_full, 0.0, y), "CVodeInit"))) return st;
    if ((st = check(P, CVodeSStolerances(P->mem, P->E.rtol, P->E.atol), "CVodeSStolerances"))) return st;
    if ((st = check(P, CVodeSetUserData(P->mem, P), "CVodeSetUserData"))) return st;
    if ((st = check(P, CVodeSetMaxNumSteps(P->mem, -1), "CVodeSetMaxNumSteps"))) return st;
    if ((st = check(P, CVodeSetMaxErrTestFails(P->mem, MAX_ERR_TEST_FAILS), "CVodeSetMaxErrTestFails"))) return st;
  }
  if (implicit && (st = linear_solver(P, P->mem, ctx, y, Jp, LSp))) return st;
  if ((st = be_max_step(P)) != MARTELLO_OK) return st;
  const int nroots = oe_nroots(&P->E);
  if (nroots > 0) {
    if (P->ark) {
      if ((st = check(P, ARKStepRootInit(P->mem, nroots, roots), "ARKStepRootInit"))) return st;
      if ((st = check(P, ARKStepSetNoInactiveRootWarn(P->mem), "ARKStepSetNoInactiveRootWarn"))) return st;
    } else {
      if ((st = check(P, CVodeRootInit(P->mem, nroots, roots), "CVodeRootInit"))) return st;
      if ((st = check(P, CVodeSetNoInactiveRootWarn(P->mem), "CVodeSetNoInactiveRootWarn"))) return st;
    }
  }
  return MARTELLO_OK;
}

/* Restart at (t, y) after an event or a kink of the load: CVODE from order 1 with its own
 * first step; ARKODE (one-step: no history) with the last step as its first. */
static int restart(ode_problem *P, double t, N_Vector y) {
  int st;
  if (P->ark) {
    double h = be_last_step(P), h_max = oe_max_step(&P->E);
    if (h_max > 0.0) h = fmin(h, h_max);
    if (h > 0.0 && (st = check(P, ARKStepSetInitStep(P->mem, h), "ARKStepSetInitStep"))) return st;
    if ((st = check(P, ARKStepReset(P->mem, t, y), "ARKStepReset"))) return st;
  } else if ((st = check(P, CVodeReInit(P->mem, t, y), "CVodeReInit"))) {
    return st;
  }
  rebase_counts(P);
  /* the held set may have changed: its bound on the steps with it */
  return be_max_step(P);
}

/* ---- ARKODE's rows by a step of their own (docs/sundials-ode.md, output rows) ---------------------
 * ARKODE's interpolant is a Hermite polynomial of degree 5 at most: inside a step of a table of
 * order q > 5 (Verner 6(5), Fehlberg 8(7)) it errs by O(h^6), more than the step's O(h^(q+1)). A
 * row at t_k inside the step [t_n-1, t_n] is then the state of one step of the same table from
 * (t_n-1, y_n-1) to t_k, on a second memory: off the trajectory, so the run's steps, events and
 * located values are what they are whatever the rows, and a row's error is the table's. */

/* Whether the table's order exceeds the interpolant's degree; the vectors the rows need. */
static int rows_setup(ode_problem *P, N_Vector y) {
  ARKodeButcherTable Bi = NULL, Be = NULL;
  if (ARKStepGetCurrentButcherTables(P->mem, &Bi, &Be) < 0)
    return fail(P, MARTELLO_ERR_EXTERNAL, "ARKODE: could not read its tables");
  const int q = Be ? Be->q : Bi ? Bi->q : 0;
  P->rows_by_step = q > ARK_INTERP_MAX_DEGREE;
  if (!P->rows_by_step) return MARTELLO_OK;
  P->y_start = N_VClone(y);
  P->y_int = N_VClone(y);
  P->y_row = N_VClone(y);
  if (!P->y_start || !P->y_int || !P->y_row) return oe_fail_memory(&P->E, "the rows' state vectors", -1.0);
  return MARTELLO_OK;
}

/* The main memory restarted (or started) at (t, y): the next step starts there. */
static void rows_restart(ode_problem *P, double t, N_Vector y) {
  if (!P->rows_by_step) return;
  P->t_int = t;
  N_VScale(1.0, y, P->y_int);
  if (ARKStepGetNumSteps(P->mem, &P->nst_seen) < 0) P->nst_seen = -1;
}

/* After ARKStepEvolve returned at tret with y: if it took a step, that step started where the
 * last one ended (t_int), and ends at ARKODE's current time (past tret at a root). */
static int rows_track(ode_problem *P, double tret, N_Vector y) {
  long nst = 0;
  if (!P->rows_by_step) return MARTELLO_OK;
  if (ARKStepGetNumSteps(P->mem, &nst) < 0) return fail(P, MARTELLO_ERR_EXTERNAL, "ARKODE: could not read its steps");
  if (nst == P->nst_seen) return MARTELLO_OK;
  P->nst_seen = nst;
  P->t_start = P->t_int;
  N_VScale(1.0, P->y_int, P->y_start);
  if (ARKStepGetCurrentTime(P->mem, &P->t_int) < 0) return fail(P, MARTELLO_ERR_EXTERNAL, "ARKODE: could not read its time");
  if (P->t_int == tret) {
    N_VScale(1.0, y, P->y_int);
    return MARTELLO_OK;
  }
  return interpolant(P, P->t_int, 0, P->y_int);
}

/* The state at t inside the last step by one step of the run's table from the step's start. */
static int row_by_step(ode_problem *P, double t, N_Vector out) {
  int st;
  const double h = t - P->t_start;
  /* ARKODE refuses a step within 100 ulps of t ("tout too close to t0"): such a row is the
   * start's state, off by its rate times those ulps */
  if (!(h > 1e3 * DBL_EPSILON * fabs(t))) {
    N_VScale(1.0, P->y_start, out);
    return MARTELLO_OK;
  }
  if (!P->row_mem) {
    if ((st = ark_create(P, P->ctx, P->t_start, P->y_start, &P->row_mem))) return st;
    if (P->kind != KIND_ERK &&
        (st = linear_solver(P, P->row_mem, P->ctx, P->y_start, &P->row_J, &P->row_LS)))
      return st;
  }
  long fe0 = 0, fi0 = 0, fe1 = 0, fi1 = 0, nls0 = 0, nls1 = 0;
  double tret = t;
  if ((st = check(P, ARKStepReset(P->row_mem, P->t_start, P->y_start), "ARKStepReset")) ||
      (st = check(P, ARKStepSetFixedStep(P->row_mem, h), "ARKStepSetFixedStep")))
    return st;
  ARKStepGetNumRhsEvals(P->row_mem, &fe0, &fi0);
  if (P->kind != KIND_ERK) ARKStepGetNumLinRhsEvals(P->row_mem, &nls0);
  int flag = ARKStepEvolve(P->row_mem, t, out, &tret, ARK_ONE_STEP);
  if (flag < 0)
    return fail(P, MARTELLO_ERR_EXTERNAL, "ARKODE: the step of the output row at t = %.9e s failed: %s (%s)", t,
                ARKStepGetReturnFlagName(flag), P->msg);
  ARKStepGetNumRhsEvals(P->row_mem, &fe1, &fi1);
  if (P->kind != KIND_ERK) ARKStepGetNumLinRhsEvals(P->row_mem, &nls1);
  /* counted as the main memory's are (be_counts) */
  P->row_rhs += (P->kind == KIND_DIRK ? fi1 - fi0 : fe1 - fe0) + (nls1 - nls0);
  return MARTELLO_OK;
}

/* The rows' memory and vectors (before their context is freed). */
static void rows_free(ode_problem *P) {
  if (P->row_mem) ARKStepFree(&P->row_mem);
  if (P->row_LS) SUNLinSolFree(P->row_LS);
  if (P->row_J) SUNMatDestroy(P->row_J);
  N_Vector rows[] = {P->y_start, P->y_int, P->y_row};
  for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++)
    if (rows[k]) N_VDestroy(rows[k]);
  P->row_LS = NULL;
  P->row_J = NULL;
  P->y_start = P->y_int = P->y_row = NULL;
}

/* ---- the run ------------------------------------------------------------------------------------ */

static int integrate(ode_problem *P, SUNContext ctx, N_Vector yy, SUNMatrix *Jp,
                     SUNLinearSolver *LSp) {
  ode_events *E = &P->E;
  int st, n = E->n;
  double *y = N_VGetArrayPointer(yy);
  if ((st = martello_model_initial_state(E->model, E->u, E->v)) != MARTELLO_OK)
    return fail(P, st, "%s: could not read the initial state", P->name);
  for (int i = 0; i < n; i++) {
    if (E->fixed[i]) E->v[i] = 0.0;
    y[2 * i] = E->u[i];
    y[2 * i + 1] = E->v[i];
  }
  if ((st = oe_initial_contacts(E, E->u, E->v)) != MARTELLO_OK) return st;
  if ((st = martello_observer_begin(E->obs, E->ev, E->u, E->v, "tighten rtol and atol")) != MARTELLO_OK)
    return st == MARTELLO_ERR_MEMORY ? st : fail(P, st, "%s: martello_observer_begin failed", P->name);
  if ((st = prepare_restart(P, 0.0, y)) != MARTELLO_OK) return st;
  P->ctx = ctx;
  if ((st = create(P, ctx, yy, Jp, LSp)) != MARTELLO_OK) return st;
  if (P->ark && (st = rows_setup(P, yy)) != MARTELLO_OK) return st;
  rows_restart(P, 0.0, yy);

  int k_out = 1;
  double t_out = oe_output_time(E, k_out), t_last = 0.0;
  if ((st = observe(P, 0.0, y, 0, 0)) != MARTELLO_OK) return st;
  oe_accepted(E, y);
  /* the stops: the loads' kinks and t_end (the output rows lie on the steps' interpolant) */
  int kink = 0;
  double t_stop = oe_next_stop(E, 0.0, E->t_end, &kink);
  if ((st = check(P, be_stop(P, t_stop), "SetStopTime"))) return st;
  const size_t n_found = (size_t)(oe_nroots(E) + 1);
  int *found = calloc(n_found, sizeof(int));
  if (!found) return oe_fail_memory(E, "the root flags", (double)(n_found * sizeof(int)));
  long steps = 0;
  st = MARTELLO_OK;
  while (t_last < E->t_end) {
    double tret = t_last;
    int flag = P->ark ? ARKStepEvolve(P->mem, E->t_end, yy, &tret, ARK_ONE_STEP)
                      : CVode(P->mem, E->t_end, yy, &tret, CV_ONE_STEP);
    if (flag < 0) {
      double tcur = t_last;
      if ((P->ark ? ARKStepGetCurrentTime(P->mem, &tcur) : CVodeGetCurrentTime(P->mem, &tcur)) < 0)
        tcur = t_last;
      E->t_now = tcur;
      for (sunindextype k = 0; k < P->N; k++)
        if (!isfinite(y[k])) E->nan_seen = 1;
      if (!isfinite(tcur)) E->nan_seen = 1;
      if (E->nan_seen)
        st = martello_observer_fail(E->obs, MARTELLO_ERR_DIVERGED, tcur, NULL);
      else
        st = fail(P, MARTELLO_ERR_EXTERNAL, "%s failed at t = %.9e s: %s (%s)", P->name, tcur,
                  be_flag(P, flag), P->msg);
      break;
    }
    E->nan_seen = 0;
    oe_new_step(E, tret);
    if ((st = rows_track(P, tret, yy)) != MARTELLO_OK) break;
    if (++steps > MAX_STEPS) {
      st = fail(P, MARTELLO_ERR_NOT_CONVERGED, "%s: more than %ld steps before t = %.9e s", P->name, MAX_STEPS, tret);
      break;
    }
    int again = 0;
    double t_r = tret;
    if (flag == (P->ark ? ARK_ROOT_RETURN : CV_ROOT_RETURN)) {
      if ((st = check(P, P->ark ? ARKStepGetRootInfo(P->mem, found) : CVodeGetRootInfo(P->mem, found),
                      "GetRootInfo")))
        break;
      again = oe_classify_roots(E, t_last, tret, y, found, &t_r);
      if (again < 0) {
        st = again;
        break;
      }
      if (!again) again = root_stays_zero(P, y, found);
    }
    /* a kink of the load: restart across it */
    if (!again && flag == (P->ark ? ARK_TSTOP_RETURN : CV_TSTOP_RETURN) && tret == t_stop &&
        kink && t_stop < E->t_end)
      again = 1;
    if (!again) {
      again = oe_boundary_events(E, t_last, tret, y, be_last_step(P), &t_r);
      if (again < 0) {
        st = again;
        break;
      }
    }
    /* a held contact's multiplier that turns tensile and back inside the step */
    if (!again && (again = oe_held_release(E, t_last, tret, y, &t_r)) < 0) {
      st = again;
      break;
    }
    if (again && t_r < tret && (st = interpolant(P, t_r, 0, yy)) != MARTELLO_OK) break;
    if ((st = oe_rows_inside(E, &t_last, t_r, &k_out, &t_out)) != MARTELLO_OK) break;
    if ((st = oe_inner_events(E, t_last, t_r, y)) != MARTELLO_OK) break;
    if ((st = oe_stretch(E, t_last, t_r, y, again)) != MARTELLO_OK) break;
    oe_keep_end_rates(E, !again);
    t_last = t_r;
    E->t_now = t_r;
    if (again) {
      if ((st = oe_restart_progress(E, t_r)) != MARTELLO_OK) break;
      if ((st = flush_counts(P)) != MARTELLO_OK) break;
      if ((st = prepare_restart(P, t_r, y)) != MARTELLO_OK) break;
    } else {
      oe_gather(E, y, E->u, E->v);
      if ((st = oe_commit(E, E->u, E->v)) != MARTELLO_OK) {
        st = fail(P, st, "%s: commit failed", P->name);
        break;
      }
      if ((st = oe_hand_work(E)) != MARTELLO_OK) break;
    }
    int at_output = t_r == t_out || (again && t_out - t_r <= 16.0 * DBL_EPSILON * t_out);
    if ((st = observe(P, t_r, y, at_output ? k_out * E->every : -1, 0)) != MARTELLO_OK) break;
    oe_accepted(E, y);
    if (at_output) {
      if (t_out >= E->t_end) {
        t_last = E->t_end;
        break;
      }
      t_out = oe_output_time(E, ++k_out);
    }
    /* ARKODE 6.4.1 with an implicit table did not continue correctly from a stop time (docs/
     * sundials-ode.md, stops of the implicit tables); the only stops now are the loads' kinks,
     * which restart it (again), and t_end */
    if (again && (st = restart(P, t_r, yy)) != MARTELLO_OK) break;
    if (again) rows_restart(P, t_r, yy);
    if (again || at_output || tret >= t_stop) {
      t_stop = oe_next_stop(E, t_r, E->t_end, &kink);
      if ((st = check(P, be_stop(P, t_stop), "SetStopTime"))) break;
    }
  }
  free(found);
  int st2 = flush_counts(P);
  if (st == MARTELLO_OK) st = st2;
  if (st == MARTELLO_OK) st = martello_observer_finish(E->obs, t_last);
  return st;
}

int martello_ode_run(martello_model *model, martello_run *run) {
  martello_settings s;
  if (model && run && martello_run_settings(run, &s) == MARTELLO_OK && s.local_stepping)
    return martello_ode_local_run(model, run);
  ode_problem prob;
  ode_problem *P = &prob;
  ode_events *E = &P->E;
  memset(P, 0, sizeof *P);
  P->name = "ODE";
  E->name = P->name;
  if (!model || !run) return MARTELLO_ERR_ARGUMENT;
  int st = martello_run_observer(run, &E->obs);
  if (st != MARTELLO_OK) return st;
  st = setup(P, model, run);
  SUNContext ctx = NULL;
  N_Vector yy = NULL;
  SUNMatrix J = NULL;
  SUNLinearSolver LS = NULL;
  if (st == MARTELLO_OK && SUNContext_Create(NULL, &ctx) != 0)
    st = fail(P, MARTELLO_ERR_EXTERNAL, "SUNContext_Create failed");
  if (st == MARTELLO_OK) {
    yy = N_VNew_Serial(P->N, ctx);
    E->ytmp = N_VNew_Serial(P->N, ctx);
    E->ytd = N_VNew_Serial(P->N, ctx);
    E->yrow = N_VNew_Serial(P->N, ctx);
    if (!yy || !E->ytmp || !E->ytd || !E->yrow) st = oe_fail_memory(E, "the ODE state vectors", -1.0);
  }
  if (st == MARTELLO_OK) st = integrate(P, ctx, yy, &J, &LS);
  if (P->mem) {
    if (P->ark) ARKStepFree(&P->mem); else CVodeFree(&P->mem);
  }
  rows_free(P);
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  if (yy) N_VDestroy(yy);
  if (E->ytmp) N_VDestroy(E->ytmp);
  if (E->ytd) N_VDestroy(E->ytd);
  if (E->yrow) N_VDestroy(E->yrow);
  if (ctx) SUNContext_Free(&ctx);
  release(P);
  return st;
}

/* ---- the pieces c/local_stepping.c drives per cluster (c/sundials_ode.h) ---------------------- */

int ode_problem_setup(ode_problem *P, martello_model *model, martello_run *run) {
  martello_settings s;
  int st = martello_run_observer(run, &P->E.obs);
  if (st == MARTELLO_OK) st = martello_run_settings(run, &s);
  if (st != MARTELLO_OK) return st;
  return s.kind == MARTELLO_INT_IDA ? ida_seam_setup(P, model, run) : setup(P, model, run);
}
void ode_problem_release(ode_problem *P) {
  ida_seam_release(P);
  if (P->mem) {
    if (P->ark) ARKStepFree(&P->mem); else CVodeFree(&P->mem);
  }
  release(P);
}
int ode_problem_create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *J, SUNLinearSolver *LS) {
  return P->ida ? ida_seam_create(P, ctx, y, J, LS) : create(P, ctx, y, J, LS);
}
int ode_problem_restart(ode_problem *P, double t, N_Vector y) {
  return P->ida ? ida_seam_restart(P, t, y) : restart(P, t, y);
}
int ode_problem_prepare_restart(ode_problem *P, double t, double *y) {
  return P->ida ? ida_seam_prepare_restart(P, t, y) : prepare_restart(P, t, y);
}
int ode_problem_flush_counts(ode_problem *P) {
  return P->ida ? ida_seam_flush_counts(P) : flush_counts(P);
}
int ode_problem_observe(ode_problem *P, double t, const double *y, int k, int row) {
  return observe(P, t, y, k, row);
}
int ode_problem_check(ode_problem *P, int flag, const char *call) {
  return P->ida ? ida_seam_check(P, flag, call) : check(P, flag, call);
}
int ode_problem_root_stays_zero(ode_problem *P, const double *y, const int *found) {
  return P->ida ? ida_seam_root_stays_zero(P, y, found) : root_stays_zero(P, y, found);
}
int ode_problem_interpolant(ode_problem *P, double t, int k, N_Vector out) {
  return P->ida ? ida_seam_interpolant(P, t, k, out) : interpolant(P, t, k, out);
}
double ode_problem_last_step(ode_problem *P) { return P->ida ? ida_seam_last_step(P) : be_last_step(P); }
int ode_problem_step(ode_problem *P, double tout, N_Vector y, double *tret) {
  if (P->ida) return ida_seam_step(P, tout, y, tret);
  int flag = P->ark ? ARKStepEvolve(P->mem, tout, y, tret, ARK_ONE_STEP) : CVode(P->mem, tout, y, tret, CV_ONE_STEP);
  if (flag < 0) return flag;
  if (flag == (P->ark ? ARK_ROOT_RETURN : CV_ROOT_RETURN)) return ODE_STEP_ROOT;
  return flag == (P->ark ? ARK_TSTOP_RETURN : CV_TSTOP_RETURN) ? ODE_STEP_TSTOP : ODE_STEP_DONE;
}
int ode_problem_root_info(ode_problem *P, int *found) {
  if (P->ida) return ida_seam_root_info(P, found);
  return check(P, P->ark ? ARKStepGetRootInfo(P->mem, found) : CVodeGetRootInfo(P->mem, found), "GetRootInfo");
}
int ode_problem_stop(ode_problem *P, double t) {
  return P->ida ? ida_seam_stop(P, t) : check(P, be_stop(P, t), "SetStopTime");
}
double ode_problem_current_time(ode_problem *P, double t_last) {
  if (P->ida) return ida_seam_current_time(P, t_last);
  double t = t_last;
  if ((P->ark ? ARKStepGetCurrentTime(P->mem, &t) : CVodeGetCurrentTime(P->mem, &t)) < 0) t = t_last;
  return t;
}
const char *ode_problem_flag(ode_problem *P, int flag) { return P->ida ? ida_seam_flag(P, flag) : be_flag(P, flag); }
