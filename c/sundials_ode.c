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
 * Events are roots (CVodeRootInit / ARKStepRootInit), as on IDA (c/ida.c): two per contact,
 * its gap delta_j (onset, separation) and its rate (an extremum of the gap: the deepest
 * point, and a contact that closes and opens inside one step), then one per switch slot of
 * the laws' branches (martello_eval_switches). At an event the state is committed on the
 * new branches and the integrator restarts there (CVodeReInit; ARKStepReset, which keeps the
 * last step as the first: a one-step method has no history to rebuild). Output times and the
 * kinks of the loads are stop times, so every history row is an accepted, committed state.
 * Steps are taken one at a time (CV_ONE_STEP, ARK_ONE_STEP); every accepted state is a sample
 * of the run's observer, with the works integrated along the solution (3-point Gauss on the
 * interpolant), the node extrema and the located peaks of c/located_peaks.c on the
 * interpolant. Contacts of the schemes lagrange and restitution are not run here (the
 * registry's compatibility table): IDA and the GSL steppers run them. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
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

/* What happens to a contact at a restart. */
enum { ACT_NONE, ACT_ONSET, ACT_SEPARATION };
/* Kinds of the table "methods" (fortran/registry.f90 METHOD_*). */
enum { KIND_BDF = 1, KIND_ADAMS = 2, KIND_ERK = 3, KIND_DIRK = 4, KIND_IMEX = 5 };
/* ARKODE's default table here: Dormand-Prince 5(4), the method value 108 (ERK id 8). */
#define ARK_DEFAULT_METHOD 108
#define MAX_STEPS 100000000L
/* error-test failures of one step before the integrator gives up (SUNDIALS' default: 7) */
#define MAX_ERR_TEST_FAILS 50

typedef struct {
  martello_model *model;
  martello_observer *obs;
  martello_eval *ev;
  int ark;                 /* 0: CVODE, 1: ARKODE */
  int kind;                /* KIND_* */
  int erk_id, dirk_id;     /* ARKODE tables (ARKODE_*_NONE when absent) */
  const char *name;        /* "CVODE" or "ARKODE": what the messages say */
  int n, nc, nsw, nl, kd, lumped;
  sunindextype N;
  double *mass;
  int *fixed, *con_a, *con_b;
  double *gap;
  int *act;
  double *u, *v, *a, *uq, *vq, *fint, *fext, *kb, *cb, *v_last;
  double *force;           /* the forces of rigid contacts for the sample: none here, all 0 */
  int *sw_a, *sw_b;
  double *sw_al, *sw_be, *sw_ga;
  /* located peaks (c/located_peaks.c), as on IDA */
  int start_rates;
  double *el0, *el1, *elc, *pv0, *pa0, *pj0, *pv1, *pa1, *pj1, *ua, *va, *aa, *jk;
  N_Vector ytd;
  void *mem;
  /* settings */
  double rtol, atol, event_tol, t_end, h_max, out_dt, dt;
  int every;
  /* works since the last hand-over */
  double dw_ext, dw_int, dw_links, dw_contact;
  double t_now;
  int nan_seen;
  char msg[240];
  long long events;
  long cnt_last[9];
} ode_problem;

/* ---- helpers ------------------------------------------------------------------------------ */

static int fail(ode_problem *P, int code, const char *fmt, ...) {
  char buf[480];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return martello_observer_fail(P->obs, code, P->t_now, buf);
}

static int fail_memory(ode_problem *P, const char *what, double bytes) {
  char of[192], line[480];
  snprintf(of, sizeof of, "%s for a scene of %d nodes and %d contacts", what, P->n, P->nc);
  martello_memory_message(of, bytes, NULL, line, (int)sizeof line);
  return martello_observer_fail(P->obs, MARTELLO_ERR_MEMORY, P->t_now, line);
}

static double node_u(int i, const double *u) { return i < 0 ? 0.0 : u[i]; }

static double penetration(const ode_problem *P, int j, const double *u) {
  return (node_u(P->con_a[j], u) - node_u(P->con_b[j], u)) - P->gap[j];
}

static double pen_rate(const ode_problem *P, int j, const double *v) {
  return node_u(P->con_a[j], v) - node_u(P->con_b[j], v);
}

static void gather(const ode_problem *P, const double *y, double *u, double *v) {
  for (int i = 0; i < P->n; i++) {
    u[i] = y[2 * i];
    v[i] = y[2 * i + 1];
  }
}

/* Move contact j strictly to side sgn by the smallest shift of one free node (the kernels
 * decide a penalty law's regime by the sign of delta; c/ida.c's nudge). */
static void nudge(ode_problem *P, int j, int sgn, double *u) {
  int a = P->con_a[j], b = P->con_b[j];
  int node = (a >= 0 && !P->fixed[a]) ? a : ((b >= 0 && !P->fixed[b]) ? b : -1);
  if (node < 0) return;
  double dir = node == a ? 1.0 : -1.0;
  double eta = 4.0 * DBL_EPSILON *
               (fabs(P->gap[j]) + fabs(node_u(a, u)) + fabs(node_u(b, u))) + DBL_MIN;
  for (int k = 0; k < 80; k++) {
    double d = penetration(P, j, u);
    if (sgn * d > 0.0) return;
    u[node] += dir * sgn * (fabs(d) + eta);
    eta *= 2.0;
  }
}

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
    st |= ARKStepGetNumGEvals(P->mem, &c[MARTELLO_COUNTER_ROOT_EVALUATIONS]);
    /* ImEx: a step evaluates both parts at a stage; count the stage evaluations once */
    if (P->kind == KIND_DIRK) c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS] = nfi;
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
  long long inc[MARTELLO_NCOUNTERS] = {0};
  for (int k = 0; k < 9; k++) {
    if (k == MARTELLO_COUNTER_EVENTS || k == MARTELLO_COUNTER_CONTACT_CHATTER_RESOLUTIONS) continue;
    inc[k] = c[k] >= P->cnt_last[k] ? c[k] - P->cnt_last[k] : c[k];
    P->cnt_last[k] = c[k];
  }
  inc[MARTELLO_COUNTER_EVENTS] = P->events;
  P->events = 0;
  return martello_observer_add_counts(P->obs, inc);
}

static void rebase_counts(ode_problem *P) {
  if (be_counts(P, P->cnt_last) != 0) memset(P->cnt_last, 0, sizeof P->cnt_last);
}

/* ---- right-hand sides, Jacobian, roots ------------------------------------------------------ */

static int finite_or_flag(ode_problem *P, const double *f) {
  for (sunindextype k = 0; k < P->N; k++)
    if (!isfinite(f[k])) {
      P->nan_seen = 1;
      return 1; /* recoverable: the integrator retries with a smaller step, then gives up */
    }
  return 0;
}

/* f = [v; M^-1 (f_ext - f_int)] */
static int rhs_full(realtype t, N_Vector yy, N_Vector ff, void *data) {
  ode_problem *P = data;
  const double *y = N_VGetArrayPointer(yy);
  double *f = N_VGetArrayPointer(ff);
  gather(P, y, P->u, P->v);
  if (martello_eval_acceleration(P->ev, t, P->u, P->v, P->a) != MARTELLO_OK) return -1;
  for (int i = 0; i < P->n; i++) {
    f[2 * i] = P->fixed[i] ? 0.0 : P->v[i];
    f[2 * i + 1] = P->a[i];
  }
  return finite_or_flag(P, f);
}

/* ImEx: the loads alone, f_E = [0; M^-1 f_ext(t)], and the internal forces, f_I = [v; -M^-1 f_int]. */
static int rhs_split(realtype t, N_Vector yy, N_Vector ff, ode_problem *P, int loads) {
  const double *y = N_VGetArrayPointer(yy);
  double *f = N_VGetArrayPointer(ff);
  gather(P, y, P->u, P->v);
  if (martello_eval_forces(P->ev, t, P->u, P->v, P->fint, P->fext) != MARTELLO_OK) return -1;
  for (int i = 0; i < P->n; i++) P->a[i] = loads ? P->fext[i] : -P->fint[i];
  if (martello_eval_solve_mass(P->ev, P->a) != MARTELLO_OK) return -1;
  for (int i = 0; i < P->n; i++) {
    f[2 * i] = loads || P->fixed[i] ? 0.0 : P->v[i];
    f[2 * i + 1] = P->a[i];
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
  const int kd = P->kd, ld = 3 * kd + 1;
  (void)t; (void)fy; (void)t1; (void)t2; (void)t3;
  gather(P, N_VGetArrayPointer(yy), P->u, P->v);
  if (martello_eval_tangent(P->ev, P->u, P->v, P->kb, P->cb) != MARTELLO_OK) return -1;
  const int band = SUNMatGetID(J) == SUNMATRIX_BAND;
#define JAC(r, c) (*(band ? &SM_ELEMENT_B(J, (r), (c)) : &SM_ELEMENT_D(J, (r), (c))))
  SUNMatZero(J);
  for (int i = 0; i < P->n; i++) {
    if (P->fixed[i]) continue;
    JAC(2 * i, 2 * i + 1) = 1.0;
    const double rm = 1.0 / P->mass[i];
    const int k0 = i - kd > 0 ? i - kd : 0, k1 = i + kd < P->n - 1 ? i + kd : P->n - 1;
    for (int k = k0; k <= k1; k++) {
      if (P->fixed[k]) continue;
      const size_t at = (size_t)(2 * kd + i - k) + (size_t)k * (size_t)ld;
      JAC(2 * i + 1, 2 * k) = -P->kb[at] * rm;
      JAC(2 * i + 1, 2 * k + 1) = -P->cb[at] * rm;
    }
  }
#undef JAC
  return 0;
}

/* (delta, delta') per contact, then one per switch slot (g > 0: the branch is left). */
static int roots(realtype t, N_Vector yy, realtype *g, void *data) {
  ode_problem *P = data;
  (void)t;
  gather(P, N_VGetArrayPointer(yy), P->uq, P->vq);
  for (int j = 0; j < P->nc; j++) {
    g[2 * j] = penetration(P, j, P->uq);
    g[2 * j + 1] = pen_rate(P, j, P->vq);
  }
  for (int s = 0; s < P->nsw; s++) {
    const int a = P->sw_a[s], b = P->sw_b[s];
    g[2 * P->nc + s] = P->sw_al[s] * (node_u(a, P->uq) - node_u(b, P->uq)) +
                       P->sw_be[s] * (node_u(a, P->vq) - node_u(b, P->vq)) + P->sw_ga[s];
  }
  return 0;
}

static void error_handler(int code, const char *module, const char *function, char *msg,
                          void *data) {
  ode_problem *P = data;
  (void)module;
  if (code < 0) snprintf(P->msg, sizeof P->msg, "%s: %s", function, msg);
}

/* ---- what the observer is handed ------------------------------------------------------------- */

static int commit(ode_problem *P, const double *u, const double *v) {
  int st = martello_eval_commit(P->ev, u, v);
  if (st == MARTELLO_OK && P->nsw > 0)
    st = martello_eval_switches(P->ev, P->sw_a, P->sw_b, P->sw_al, P->sw_be, P->sw_ga);
  return st == MARTELLO_OK ? st : fail(P, st, "%s: commit failed", P->name);
}

static int hand_work(ode_problem *P) {
  int st = martello_observer_work(P->obs, P->dw_ext, P->dw_int, P->dw_links, P->dw_contact, 0.0);
  P->dw_ext = P->dw_int = P->dw_links = P->dw_contact = 0.0;
  return st == MARTELLO_OK ? st : fail(P, st, "%s: could not hand the works to the observer", P->name);
}

/* An accepted, committed state at t (a from the right-hand side there: no contact force is
 * the method's own) as a sample; k: its output grid point or -1. */
static int observe(ode_problem *P, double t, const double *y, int k) {
  gather(P, y, P->u, P->v);
  int st = martello_eval_acceleration(P->ev, t, P->u, P->v, P->a);
  if (st != MARTELLO_OK) return fail(P, st, "%s: acceleration failed at t = %.9e s", P->name, t);
  return martello_observer_sample(P->obs, P->ev, t, P->u, P->v, P->a, P->force, k);
}

static int dky(ode_problem *P, double t, int k, N_Vector out) {
  int flag = be_dky(P, t, k, out);
  if (flag < 0)
    return fail(P, MARTELLO_ERR_EXTERNAL, "%s: the interpolant failed at t = %.9e s: %s", P->name, t,
                be_flag(P, flag));
  return MARTELLO_OK;
}

/* The works over [t0, t1] on the interpolant, 3-point Gauss-Legendre (c/ida.c). */
static int work_quadrature(ode_problem *P, double t0, double t1, N_Vector ytmp) {
  static const double xg[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  if (!(t1 > t0)) return MARTELLO_OK;
  double h = t1 - t0, we = 0.0, wi = 0.0, wl = 0.0, wc = 0.0, power[5];
  for (int k = 0; k < 3; k++) {
    double tk = t0 + 0.5 * h * (1.0 + xg[k]);
    int st = dky(P, tk, 0, ytmp);
    if (st != MARTELLO_OK) return st;
    gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
    st = martello_eval_forces(P->ev, tk, P->uq, P->vq, P->fint, P->fext);
    if (st == MARTELLO_OK) st = martello_eval_power(P->ev, power);
    if (st != MARTELLO_OK) return fail(P, st, "%s: force evaluation failed at t = %.9e s", P->name, tk);
    we += wg[k] * power[0];
    wi += wg[k] * power[1];
    wl += wg[k] * power[3];
    wc += wg[k] * power[4];
  }
  P->dw_ext += h * we;
  P->dw_int += h * wi;
  P->dw_links += h * wl;
  P->dw_contact += h * wc;
  return MARTELLO_OK;
}

/* The extrema of u inside [t0, t1]: where v changes sign against the last state, bisection
 * of v on the interpolant (c/ida.c's node_extrema). */
static int node_extrema(ode_problem *P, double t0, double t1, const double *y1, N_Vector ytmp) {
  for (int i = 0; i < P->n; i++) {
    const double v0 = P->v_last[i], v1 = y1[2 * i + 1];
    int is_max, st;
    if (P->fixed[i]) continue;
    if (v0 > 0.0 && v1 <= 0.0) is_max = 1;
    else if (v0 < 0.0 && v1 >= 0.0) is_max = 0;
    else continue;
    double lo = t0, hi = t1, u = y1[2 * i];
    for (int it = 0; it < 200 && hi - lo > fmax(P->event_tol, 4.0 * DBL_EPSILON * fabs(hi)); it++) {
      const double tm = 0.5 * (lo + hi);
      if ((st = dky(P, tm, 0, ytmp)) != MARTELLO_OK) return st;
      if ((N_VGetArrayPointer(ytmp)[2 * i + 1] > 0.0) == (v0 > 0.0)) lo = tm; else hi = tm;
    }
    if (hi < t1) {
      if ((st = dky(P, hi, 0, ytmp)) != MARTELLO_OK) return st;
      u = N_VGetArrayPointer(ytmp)[2 * i];
    }
    st = martello_observer_extremum(P->obs, i, hi, u, is_max);
    if (st != MARTELLO_OK) return fail(P, st, "%s: martello_observer_extremum failed", P->name);
  }
  return MARTELLO_OK;
}

/* u, v, a at t on the interpolant (y and y'; a is the v rows of y'), with the jerks and the
 * element rates into e, jerk. */
static int interpolated_rates(ode_problem *P, double t, double *e, double *jerk) {
  int st = dky(P, t, 0, P->ytd);
  if (st != MARTELLO_OK) return st;
  gather(P, N_VGetArrayPointer(P->ytd), P->ua, P->va);
  if ((st = dky(P, t, 1, P->ytd)) != MARTELLO_OK) return st;
  for (int i = 0; i < P->n; i++) P->aa[i] = N_VGetArrayPointer(P->ytd)[2 * i + 1];
  st = martello_peak_rates(P->ev, t, P->ua, P->va, P->aa, P->nc, P->nl, e, jerk);
  return st == MARTELLO_OK ? st : fail(P, st, "%s: the rates of the peaks failed at t = %.9e s", P->name, t);
}

static int peak_probe(void *ctx, double t, int kind, int j, double *q, double *r) {
  ode_problem *P = ctx;
  int st = interpolated_rates(P, t, P->elc, P->jk);
  if (st != MARTELLO_OK) return st;
  martello_peak_pick(kind, j, P->nc, P->nl, P->va, P->aa, P->jk, P->elc, q, r);
  return MARTELLO_OK;
}

static int peak_skip(void *ctx, int kind, int j) {
  ode_problem *P = ctx;
  if (kind == MARTELLO_PEAK_V || kind == MARTELLO_PEAK_A) return P->fixed[j];
  if (kind == MARTELLO_PEAK_PEN || kind == MARTELLO_PEAK_FORCE) return !martello_observer_in_phase(P->obs, j);
  return 0;
}

/* The peaks inside [t0, t1] on the interpolant (c/located_peaks.c); the start's rates kept
 * from the last stretch's end while no restart came between (P->start_rates). */
static int located_peaks(ode_problem *P, double t0, double t1) {
  const size_t nb = sizeof(double) * (size_t)P->n;
  martello_peak_ends e;
  int st;
  if (!(t1 > t0)) return MARTELLO_OK;
  if (!P->start_rates) {
    if ((st = interpolated_rates(P, t0, P->el0, P->pj0)) != MARTELLO_OK) return st;
    memcpy(P->pv0, P->va, nb);
    memcpy(P->pa0, P->aa, nb);
  }
  if ((st = interpolated_rates(P, t1, P->el1, P->pj1)) != MARTELLO_OK) return st;
  memcpy(P->pv1, P->va, nb);
  memcpy(P->pa1, P->aa, nb);
  memset(&e, 0, sizeof e);
  martello_peak_ends_set(&e, 0, P->n, P->nc, P->nl, P->pv0, P->pa0, P->pj0, P->el0);
  martello_peak_ends_set(&e, 1, P->n, P->nc, P->nl, P->pv1, P->pa1, P->pj1, P->el1);
  e.skip = peak_skip;
  return martello_locate_peaks(P->obs, &e, t0, t1, P->rtol, P->event_tol, peak_probe, P);
}

static void keep_end_rates(ode_problem *P, int unchanged) {
  double *tmp;
  P->start_rates = unchanged;
  if (!unchanged) return;
  tmp = P->el0; P->el0 = P->el1; P->el1 = tmp;
  tmp = P->pj0; P->pj0 = P->pj1; P->pj1 = tmp;
  tmp = P->pv0; P->pv0 = P->pv1; P->pv1 = tmp;
  tmp = P->pa0; P->pa0 = P->pa1; P->pa1 = tmp;
}

/* ---- events ------------------------------------------------------------------------------------ */

/* Bisection on the interpolant for the crossing of delta_j in [tl, tr]: a time on the tl
 * side within event_tol. */
static int locate(ode_problem *P, int j, double tl, double tr, N_Vector ytmp, double *t_cross) {
  int st = dky(P, tl, 0, ytmp);
  if (st != MARTELLO_OK) return st;
  gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
  int left_positive = penetration(P, j, P->uq) > 0.0;
  for (int it = 0; it < 200 && tr - tl > fmax(P->event_tol, 4.0 * DBL_EPSILON * fabs(tr)); it++) {
    double tm = 0.5 * (tl + tr);
    if ((st = dky(P, tm, 0, ytmp)) != MARTELLO_OK) return st;
    gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
    if ((penetration(P, j, P->uq) > 0.0) == left_positive) tl = tm; else tr = tm;
  }
  *t_cross = tl;
  return MARTELLO_OK;
}

/* What the roots at tret mean (c/ida.c's classify_roots, penalty contacts): 1 with *t_r and
 * P->act if the integrator restarts, 0 if they were extrema of gaps, < 0 on failure. */
static int classify_roots(ode_problem *P, double t_last, double tret, const double *y,
                          const int *found, N_Vector ytmp, double *t_r) {
  gather(P, y, P->u, P->v);
  double best = tret;
  int jbest = -1, kbest = ACT_NONE;
  for (int j = 0; j < P->nc; j++) {
    if (!found[2 * j + 1] || found[2 * j]) continue;
    double d = penetration(P, j, P->u);
    int want = ACT_NONE, touching = martello_observer_in_phase(P->obs, j);
    if (!touching && d > 0.0) want = ACT_ONSET;
    else if (touching && d < 0.0) want = ACT_SEPARATION;
    if (want == ACT_NONE) continue;
    double tc;
    int st = locate(P, j, t_last, tret, ytmp, &tc);
    if (st != MARTELLO_OK) return st;
    if (jbest < 0 || tc < best) {
      best = tc;
      jbest = j;
      kbest = want;
    }
  }
  if (jbest >= 0) {
    P->act[jbest] = kbest;
    *t_r = best;
    return 1;
  }
  int any = 0;
  for (int j = 0; j < P->nc; j++) {
    int dir = found[2 * j], touching = martello_observer_in_phase(P->obs, j);
    if (dir > 0 && !touching) P->act[j] = ACT_ONSET;
    else if (dir < 0 && touching) P->act[j] = ACT_SEPARATION;
    any |= P->act[j] != ACT_NONE;
  }
  *t_r = tret;
  return any;
}

/* A root exactly 0 at the return (identical neighbours, docs/problems.md P7) would stop the
 * integrator again at once: a restart with no event lets it move away (c/ida.c). */
static int root_stays_zero(ode_problem *P, const double *y, const int *found) {
  gather(P, y, P->uq, P->vq);
  for (int j = 0; j < P->nc; j++)
    if ((found[2 * j] && penetration(P, j, P->uq) == 0.0) ||
        (found[2 * j + 1] && pen_rate(P, j, P->vq) == 0.0))
      return 1;
  return 0;
}

/* After a step without a root: a contact on the wrong side of its phase (an event time that
 * coincides with a stop lands on delta = 0, where no sign change is seen; c/ida.c). */
static int boundary_events(ode_problem *P, double t_last, double tret, const double *y,
                           N_Vector ytmp, double *t_r) {
  gather(P, y, P->u, P->v);
  double best = tret, h_last = be_last_step(P), vmax = 0.0;
  int jbest = -1, kbest = ACT_NONE;
  for (int i = 0; i < P->n; i++) vmax = fmax(vmax, fabs(P->v[i]));
  double wtol = 10.0 * (P->rtol * vmax + P->atol);
  for (int j = 0; j < P->nc; j++) {
    int want = ACT_NONE, touching = martello_observer_in_phase(P->obs, j);
    double d = penetration(P, j, P->u), w = pen_rate(P, j, P->v);
    double on = 64.0 * DBL_EPSILON *
                (fabs(node_u(P->con_a[j], P->u)) + fabs(node_u(P->con_b[j], P->u)) + fabs(P->gap[j]) +
                 fabs(w) * (fabs(tret) + fabs(h_last)));
    if (!touching && (d > 0.0 || (d >= -on && w > wtol))) want = ACT_ONSET;
    else if (touching && (d < 0.0 || (d <= on && w < -wtol))) want = ACT_SEPARATION;
    if (want == ACT_NONE) continue;
    double tc = tret;
    int wrong_side = touching ? d < 0.0 : d > 0.0;
    if (wrong_side && fabs(d) > on && tret > t_last) {
      int st = locate(P, j, t_last, tret, ytmp, &tc);
      if (st != MARTELLO_OK) return st;
    }
    if (jbest < 0 || tc < best) {
      best = tc;
      jbest = j;
      kbest = want;
    }
  }
  if (jbest < 0) return 0;
  P->act[jbest] = kbest;
  *t_r = best;
  return 1;
}

/* The state at a restart: each acting contact put on its new side and its phase changed,
 * then committed on the new branches. */
static int prepare_restart(ode_problem *P, double t, double *y) {
  gather(P, y, P->u, P->v);
  for (int j = 0; j < P->nc; j++) {
    double w = pen_rate(P, j, P->v);
    if (P->act[j] == ACT_ONSET) {
      nudge(P, j, +1, P->u);
      martello_observer_set_phase(P->obs, j, 1, t, w);
      P->events++;
    } else if (P->act[j] == ACT_SEPARATION) {
      nudge(P, j, -1, P->u);
      martello_observer_set_phase(P->obs, j, 0, t, w);
      P->events++;
    }
    P->act[j] = ACT_NONE;
  }
  for (int i = 0; i < P->n; i++) y[2 * i] = P->u[i];
  int st = commit(P, P->u, P->v);
  return st == MARTELLO_OK ? hand_work(P) : st;
}

/* ---- set-up ------------------------------------------------------------------------------------- */

static void *take(size_t count, size_t size, double *failed) {
  void *p = calloc(count > 0 ? count : 1, size);
  if (!p && *failed == 0.0) *failed = (double)(count > 0 ? count : 1) * (double)size;
  return p;
}

static void release(ode_problem *P) {
  void *all[] = {P->mass, P->force, P->fixed, P->con_a, P->con_b, P->gap, P->act, P->u, P->v, P->a,
                 P->uq, P->vq, P->fint, P->fext, P->kb, P->cb, P->v_last, P->sw_a, P->sw_b,
                 P->sw_al, P->sw_be, P->sw_ga, P->el0, P->el1, P->elc, P->pv0, P->pa0,
                 P->pj0, P->pv1, P->pa1, P->pj1, P->ua, P->va, P->aa, P->jk};
  for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) free(all[k]);
  if (P->ev) martello_eval_free(&P->ev);
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
  int st, n, nc, ncp;
  double failed = 0.0;
  martello_settings s;
  P->model = model;
  if ((st = martello_run_settings(run, &s)) != MARTELLO_OK) return st;
  P->ark = s.kind == MARTELLO_INT_ARKODE;
  P->name = P->ark ? "ARKODE" : "CVODE";
  P->rtol = s.rtol;
  P->atol = s.atol;
  P->event_tol = s.event_tol;
  P->t_end = s.t_end;
  P->h_max = s.h_max;
  P->every = s.every;
  P->out_dt = s.dt * s.every;
  P->dt = s.dt;
  if ((st = choose_method(P, s.method)) != MARTELLO_OK) return st;
  if ((st = martello_model_topology(model, &n, &nc, NULL, NULL, NULL, NULL, NULL, NULL, NULL,
                                    &ncp)) != MARTELLO_OK)
    return fail(P, st, "%s: could not read the model", P->name);
  P->n = n;
  P->nc = nc;
  P->N = 2 * (sunindextype)n;
  size_t un = (size_t)n, ucn = (size_t)nc;
  P->mass = take(un, sizeof(double), &failed);
  P->fixed = take(un, sizeof(int), &failed);
  P->con_a = take(ucn, sizeof(int), &failed);
  P->con_b = take(ucn, sizeof(int), &failed);
  P->gap = take(ucn, sizeof(double), &failed);
  P->act = take(ucn, sizeof(int), &failed);
  P->force = take(ucn, sizeof(double), &failed);
  int *scheme = take(ucn, sizeof(int), &failed);
  double *rest = take(ucn, sizeof(double), &failed);
  double **work[] = {&P->u, &P->v, &P->a, &P->uq, &P->vq, &P->fint, &P->fext, &P->v_last,
                     &P->pv0, &P->pa0, &P->pj0, &P->pv1, &P->pa1, &P->pj1, &P->ua, &P->va,
                     &P->aa, &P->jk};
  for (size_t k = 0; k < sizeof work / sizeof work[0]; k++) *work[k] = take(un, sizeof(double), &failed);
  if (failed > 0.0) {
    free(scheme);
    free(rest);
    return fail_memory(P, "an array of the ODE state", failed);
  }
  st = martello_model_topology(model, &n, &nc, P->mass, P->fixed, P->con_a, P->con_b, scheme,
                               P->gap, rest, &ncp);
  for (int j = 0; j < nc && st == MARTELLO_OK; j++)
    if (scheme[j] != MARTELLO_SCHEME_PENALTY)
      st = fail(P, MARTELLO_ERR_UNSUPPORTED,
                "contact %d: only penalty contacts run on %s (ida, rkf45, rk8pd and msbdf run "
                "lagrange and restitution contacts)", j, P->name);
  free(scheme);
  free(rest);
  if (st != MARTELLO_OK) return st;
  if ((st = martello_eval_create(model, &P->ev)) == MARTELLO_ERR_MEMORY) {
    char line[480];
    martello_model_message(model, line, (int)sizeof line);
    return martello_observer_fail(P->obs, st, P->t_now, line);
  }
  if (st != MARTELLO_OK) return fail(P, st, "%s: could not create the force evaluator", P->name);
  if ((st = martello_eval_link_count(P->ev, &P->nl)) != MARTELLO_OK ||
      (st = martello_eval_bandwidth(P->ev, &P->kd, &P->lumped)) != MARTELLO_OK)
    return fail(P, st, "%s: could not read the evaluator", P->name);
  {
    const size_t ne = 4 * ((size_t)nc + (size_t)P->nl), nb = (size_t)(3 * P->kd + 1) * un;
    double **el[] = {&P->el0, &P->el1, &P->elc};
    for (size_t k = 0; k < sizeof el / sizeof el[0]; k++) *el[k] = take(ne, sizeof(double), &failed);
    P->kb = take(nb, sizeof(double), &failed);
    P->cb = take(nb, sizeof(double), &failed);
    if (failed > 0.0) return fail_memory(P, "an array of the ODE state", failed);
  }
  if ((st = martello_eval_use_branches(P->ev, &P->nsw)) != MARTELLO_OK)
    return fail(P, st, "%s: martello_eval_use_branches failed", P->name);
  P->sw_a = take((size_t)P->nsw, sizeof(int), &failed);
  P->sw_b = take((size_t)P->nsw, sizeof(int), &failed);
  P->sw_al = take((size_t)P->nsw, sizeof(double), &failed);
  P->sw_be = take((size_t)P->nsw, sizeof(double), &failed);
  P->sw_ga = take((size_t)P->nsw, sizeof(double), &failed);
  if (failed > 0.0) return fail_memory(P, "an array of the ODE state", failed);
  if (P->nsw > 0 &&
      (st = martello_eval_switches(P->ev, P->sw_a, P->sw_b, P->sw_al, P->sw_be, P->sw_ga)) != MARTELLO_OK)
    return fail(P, st, "%s: martello_eval_switches failed", P->name);
  return MARTELLO_OK;
}

static int check(ode_problem *P, int flag, const char *call) {
  if (flag >= 0) return MARTELLO_OK;
  return fail(P, MARTELLO_ERR_EXTERNAL, "%s failed: %s", call, be_flag(P, flag));
}

/* Create the integrator at (0, y): method, tolerances, the linear solver of its Newton
 * systems (none for an explicit table), roots. */
static int create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *Jp, SUNLinearSolver *LSp) {
  int st;
  const int implicit = P->kind != KIND_ERK;
  if (P->ark) {
    ARKRhsFn fe = P->kind == KIND_ERK ? rhs_full : P->kind == KIND_IMEX ? rhs_loads : NULL;
    ARKRhsFn fi = P->kind == KIND_DIRK ? rhs_full : P->kind == KIND_IMEX ? rhs_internal : NULL;
    P->mem = ARKStepCreate(fe, fi, 0.0, y, ctx);
    if (!P->mem) return fail_memory(P, "the ARKODE solver memory (ARKStepCreate)", -1.0);
    if ((st = check(P, ARKStepSetErrHandlerFn(P->mem, error_handler, P), "ARKStepSetErrHandlerFn"))) return st;
    if ((st = check(P, ARKStepSetTableNum(P->mem, P->dirk_id, P->erk_id), "ARKStepSetTableNum"))) return st;
    if ((st = check(P, ARKStepSStolerances(P->mem, P->rtol, P->atol), "ARKStepSStolerances"))) return st;
    if ((st = check(P, ARKStepSetUserData(P->mem, P), "ARKStepSetUserData"))) return st;
    if ((st = check(P, ARKStepSetMaxNumSteps(P->mem, -1), "ARKStepSetMaxNumSteps"))) return st;
    /* a law whose force has an unbounded derivative at first touch (Jankowski's damping goes
     * as delta^(1/4)) fails the error test of the first steps in contact many times over before
     * the step is small enough: ARKODE's default of 7 failures stopped P2, P5 and P7's
     * Jankowski scenes at onset (h ~ 1e-8 s) */
    if ((st = check(P, ARKStepSetMaxErrTestFails(P->mem, MAX_ERR_TEST_FAILS), "ARKStepSetMaxErrTestFails"))) return st;
    /* the interpolant of the steps, for the roots, the works and the located peaks: the
     * highest degree ARKODE has (5) */
    if ((st = check(P, ARKStepSetInterpolantDegree(P->mem, ARK_INTERP_MAX_DEGREE),
                    "ARKStepSetInterpolantDegree"))) return st;
    if (P->h_max > 0.0 && (st = check(P, ARKStepSetMaxStep(P->mem, P->h_max), "ARKStepSetMaxStep"))) return st;
    if (implicit && (st = check(P, ARKStepSetDeduceImplicitRhs(P->mem, SUNTRUE),
                                "ARKStepSetDeduceImplicitRhs"))) return st;
  } else {
    P->mem = CVodeCreate(P->kind == KIND_ADAMS ? CV_ADAMS : CV_BDF, ctx);
    if (!P->mem) return fail_memory(P, "the CVODE solver memory (CVodeCreate)", -1.0);
    if ((st = check(P, CVodeSetErrHandlerFn(P->mem, error_handler, P), "CVodeSetErrHandlerFn"))) return st;
    if ((st = check(P, CVodeInit(P->mem, rhs_full, 0.0, y), "CVodeInit"))) return st;
    if ((st = check(P, CVodeSStolerances(P->mem, P->rtol, P->atol), "CVodeSStolerances"))) return st;
    if ((st = check(P, CVodeSetUserData(P->mem, P), "CVodeSetUserData"))) return st;
    if ((st = check(P, CVodeSetMaxNumSteps(P->mem, -1), "CVodeSetMaxNumSteps"))) return st;
    if ((st = check(P, CVodeSetMaxErrTestFails(P->mem, MAX_ERR_TEST_FAILS), "CVodeSetMaxErrTestFails"))) return st;
    if (P->h_max > 0.0 && (st = check(P, CVodeSetMaxStep(P->mem, P->h_max), "CVodeSetMaxStep"))) return st;
  }
  if (implicit) {
    /* the analytic Jacobian with a lumped mass, banded where the band is narrower than half
     * the state (c/ida.c's rule); SUNDIALS' dense difference quotients where a mass coupling
     * makes M^-1 full */
    const sunindextype bw = 2 * (sunindextype)P->kd + 1;
    const int band = P->lumped && 2 * bw + 1 < P->N / 2;
    *Jp = band ? SUNBandMatrix(P->N, bw, bw, ctx) : SUNDenseMatrix(P->N, P->N, ctx);
    if (!*Jp) return fail_memory(P, "the Jacobian matrix", -1.0);
    *LSp = band ? SUNLinSol_Band(y, *Jp, ctx) : SUNLinSol_Dense(y, *Jp, ctx);
    if (!*LSp) return fail_memory(P, "the linear solver", -1.0);
    if (P->ark) {
      if ((st = check(P, ARKStepSetLinearSolver(P->mem, *LSp, *Jp), "ARKStepSetLinearSolver"))) return st;
      if (P->lumped && (st = check(P, ARKStepSetJacFn(P->mem, jacobian), "ARKStepSetJacFn"))) return st;
    } else {
      if ((st = check(P, CVodeSetLinearSolver(P->mem, *LSp, *Jp), "CVodeSetLinearSolver"))) return st;
      if (P->lumped && (st = check(P, CVodeSetJacFn(P->mem, jacobian), "CVodeSetJacFn"))) return st;
    }
  }
  const int nroots = 2 * P->nc + P->nsw;
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
    double h = be_last_step(P);
    if (h > 0.0 && (st = check(P, ARKStepSetInitStep(P->mem, h), "ARKStepSetInitStep"))) return st;
    if ((st = check(P, ARKStepReset(P->mem, t, y), "ARKStepReset"))) return st;
  } else if ((st = check(P, CVodeReInit(P->mem, t, y), "CVodeReInit"))) {
    return st;
  }
  rebase_counts(P);
  return MARTELLO_OK;
}

static double next_stop(ode_problem *P, double t, double t_out) {
  double tb = DBL_MAX;
  if (martello_eval_next_breakpoint(P->ev, t, &tb) != MARTELLO_OK) tb = DBL_MAX;
  return fmin(tb, t_out);
}

/* ---- the run ------------------------------------------------------------------------------------ */

static int integrate(ode_problem *P, SUNContext ctx, N_Vector yy, N_Vector ytmp, SUNMatrix *Jp,
                     SUNLinearSolver *LSp) {
  int st, n = P->n;
  double *y = N_VGetArrayPointer(yy);
  if ((st = martello_model_initial_state(P->model, P->u, P->v)) != MARTELLO_OK)
    return fail(P, st, "%s: could not read the initial state", P->name);
  for (int i = 0; i < n; i++) {
    if (P->fixed[i]) P->v[i] = 0.0;
    y[2 * i] = P->u[i];
    y[2 * i + 1] = P->v[i];
  }
  for (int j = 0; j < P->nc; j++)
    if (penetration(P, j, P->u) == 0.0 && pen_rate(P, j, P->v) > 0.0) P->act[j] = ACT_ONSET;
  if ((st = martello_observer_begin(P->obs, P->ev, P->u, P->v, "tighten rtol and atol")) != MARTELLO_OK)
    return st == MARTELLO_ERR_MEMORY ? st : fail(P, st, "%s: martello_observer_begin failed", P->name);
  if ((st = prepare_restart(P, 0.0, y)) != MARTELLO_OK) return st;
  if ((st = create(P, ctx, yy, Jp, LSp)) != MARTELLO_OK) return st;

  int k_out = 1, same_time = 0;
  double t_out = fmin((double)P->every * P->dt, P->t_end), t_last = 0.0, t_prev_restart = -1.0;
  if ((st = observe(P, 0.0, y, 0)) != MARTELLO_OK) return st;
  for (int i = 0; i < n; i++) P->v_last[i] = y[2 * i + 1];
  double t_stop = next_stop(P, 0.0, t_out);
  if ((st = check(P, be_stop(P, t_stop), "SetStopTime"))) return st;
  const size_t n_found = (size_t)(2 * P->nc + P->nsw + 1);
  int *found = calloc(n_found, sizeof(int));
  if (!found) return fail_memory(P, "the root flags", (double)(n_found * sizeof(int)));
  long steps = 0;
  st = MARTELLO_OK;
  while (t_last < P->t_end) {
    double tret = t_last;
    int flag = P->ark ? ARKStepEvolve(P->mem, t_out, yy, &tret, ARK_ONE_STEP)
                      : CVode(P->mem, t_out, yy, &tret, CV_ONE_STEP);
    if (flag < 0) {
      double tcur = t_last;
      if ((P->ark ? ARKStepGetCurrentTime(P->mem, &tcur) : CVodeGetCurrentTime(P->mem, &tcur)) < 0)
        tcur = t_last;
      P->t_now = tcur;
      for (sunindextype k = 0; k < P->N; k++)
        if (!isfinite(y[k])) P->nan_seen = 1;
      if (!isfinite(tcur)) P->nan_seen = 1;
      if (P->nan_seen)
        st = martello_observer_fail(P->obs, MARTELLO_ERR_DIVERGED, tcur, NULL);
      else
        st = fail(P, MARTELLO_ERR_EXTERNAL, "%s failed at t = %.9e s: %s (%s)", P->name, tcur,
                  be_flag(P, flag), P->msg);
      break;
    }
    P->nan_seen = 0;
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
      again = classify_roots(P, t_last, tret, y, found, ytmp, &t_r);
      if (again < 0) {
        st = again;
        break;
      }
      if (!again) again = root_stays_zero(P, y, found);
      for (int s = 0; s < P->nsw && !again; s++)
        if (found[2 * P->nc + s]) again = 1;
    }
    /* a kink of the load: restart across it */
    if (!again && flag == (P->ark ? ARK_TSTOP_RETURN : CV_TSTOP_RETURN) && tret == t_stop &&
        t_stop < t_out)
      again = 1;
    if (!again) {
      again = boundary_events(P, t_last, tret, y, ytmp, &t_r);
      if (again < 0) {
        st = again;
        break;
      }
    }
    if (again && t_r < tret && (st = dky(P, t_r, 0, yy)) != MARTELLO_OK) break;
    if ((st = work_quadrature(P, t_last, t_r, ytmp)) != MARTELLO_OK) break;
    if ((st = node_extrema(P, t_last, t_r, y, ytmp)) != MARTELLO_OK) break;
    if ((st = located_peaks(P, t_last, t_r)) != MARTELLO_OK) break;
    keep_end_rates(P, !again);
    t_last = t_r;
    P->t_now = t_r;
    if (again) {
      same_time = t_r - t_prev_restart <= 1e-12 * fmax(fabs(t_r), P->out_dt) ? same_time + 1 : 0;
      t_prev_restart = t_r;
      if (same_time > 8 * (P->nc + 2)) {
        st = fail(P, MARTELLO_ERR_NOT_CONVERGED, "%s: contact events keep recurring at t = %.9e s without progress", P->name, t_r);
        break;
      }
      if ((st = flush_counts(P)) != MARTELLO_OK) break;
      if ((st = prepare_restart(P, t_r, y)) != MARTELLO_OK) break;
    } else {
      gather(P, y, P->u, P->v);
      if ((st = commit(P, P->u, P->v)) != MARTELLO_OK) break;
      if ((st = hand_work(P)) != MARTELLO_OK) break;
    }
    int at_output = t_r == t_out || (again && t_out - t_r <= 16.0 * DBL_EPSILON * t_out);
    if ((st = observe(P, t_r, y, at_output ? k_out * P->every : -1)) != MARTELLO_OK) break;
    for (int i = 0; i < n; i++) P->v_last[i] = y[2 * i + 1];
    if (at_output) {
      if (t_out >= P->t_end) {
        t_last = P->t_end;
        break;
      }
      k_out++;
      t_out = fmin((double)(k_out * P->every) * P->dt, P->t_end);
      if (P->t_end - t_out <= 1e-9 * P->out_dt) t_out = P->t_end;
    }
    /* ARKODE 6.4.1 with an implicit table does not continue correctly from a stop time: on
     * a free oscillator (docs/sundials-ode.md) 30 output stops left u off by 1e-7 .. 2e-5
     * whatever rtol (kvaerno-5-3-4, sdirk-5-3-4, kvaerno-7-4-5), one stop 1e-13. A reset at
     * every stop (a one-step method loses no history), with the implicit stages' f deduced
     * from the Newton solution (ARKStepSetDeduceImplicitRhs), leaves 1e-12 .. 1e-15. */
    const int arkode_stop = P->ark && P->kind != KIND_ERK && !again &&
                            flag == ARK_TSTOP_RETURN && t_r < P->t_end;
    if (arkode_stop && (st = flush_counts(P)) != MARTELLO_OK) break;
    if ((again || arkode_stop) && (st = restart(P, t_r, yy)) != MARTELLO_OK) break;
    if (again || at_output || tret >= t_stop) {
      t_stop = next_stop(P, t_r, t_out);
      if ((st = check(P, be_stop(P, t_stop), "SetStopTime"))) break;
    }
  }
  free(found);
  int st2 = flush_counts(P);
  if (st == MARTELLO_OK) st = st2;
  if (st == MARTELLO_OK) st = martello_observer_finish(P->obs, t_last);
  return st;
}

int martello_ode_run(martello_model *model, martello_run *run) {
  ode_problem prob;
  ode_problem *P = &prob;
  memset(P, 0, sizeof *P);
  P->name = "ODE";
  if (!model || !run) return MARTELLO_ERR_ARGUMENT;
  int st = martello_run_observer(run, &P->obs);
  if (st != MARTELLO_OK) return st;
  st = setup(P, model, run);
  SUNContext ctx = NULL;
  N_Vector yy = NULL, ytmp = NULL;
  SUNMatrix J = NULL;
  SUNLinearSolver LS = NULL;
  if (st == MARTELLO_OK && SUNContext_Create(NULL, &ctx) != 0)
    st = fail(P, MARTELLO_ERR_EXTERNAL, "SUNContext_Create failed");
  if (st == MARTELLO_OK) {
    yy = N_VNew_Serial(P->N, ctx);
    ytmp = N_VNew_Serial(P->N, ctx);
    P->ytd = N_VNew_Serial(P->N, ctx);
    if (!yy || !ytmp || !P->ytd) st = fail_memory(P, "the ODE state vectors", -1.0);
  }
  if (st == MARTELLO_OK) st = integrate(P, ctx, yy, ytmp, &J, &LS);
  if (P->mem) {
    if (P->ark) ARKStepFree(&P->mem); else CVodeFree(&P->mem);
  }
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  if (yy) N_VDestroy(yy);
  if (ytmp) N_VDestroy(ytmp);
  if (P->ytd) N_VDestroy(P->ytd);
  if (ctx) SUNContext_Free(&ctx);
  release(P);
  return st;
}
