/* DAE integration on SUNDIALS IDA (docs/ida.md).
 *
 * State y, node by node: [u_i, v_i] followed, after the first node of each rigid contact r
 * (scheme lagrange or restitution), by its multiplier P_r and its GGL multiplier mu_r, so that
 * a chain keeps a narrow band. Residual (acceleration form, a = M^-1 (f_ext - f_int) from the
 * kernels' evaluator, penalty contacts inside f_int):
 *
 *   F_u = u' - v + M^-1 B mu          F_v = v' - a(t, u, v) + M^-1 B P
 *   closed rigid contact r:  F_P = B_r^T v   (velocity constraint, delta_r' = 0)
 *                            F_mu = delta_r  (position constraint, Gear-Gupta-Leimkuhler)
 *   open rigid contact r:    F_P = P_r,  F_mu = mu_r  (both held at 0)
 *
 * B_r = e_a - e_b, delta_r = u_a - u_b - gap_r, P_r >= 0 compresses (pushes a back). The
 * closed-contact rows are the stabilised index-2 (GGL) form: no drift, P and mu algebraic
 * (IDASetId 0) and out of the local error test (IDASetSuppressAlg), as usual for index 2.
 *
 * Events are roots of IDA (IDARootInit), those of every SUNDIALS integrator here (c/ode_events.c:
 * gaps and their rates, the state's multiplier of a closed rigid contact, the laws' switches);
 * at an event the state is made consistent there (penalty phases, impacts, closings by the
 * accumulation rule, releases) and IDA restarts (IDAReInit). The penalty laws whose force is
 * continuous at their switches are stepped across instead, their onsets and separations located
 * inside the steps on IDA's interpolant (docs/ida.md, switching surfaces). Steps are taken in
 * IDA_ONE_STEP mode so that path-dependent
 * links commit at every accepted step. The kinks of the loads and t_end are the only stop times:
 * IDA steps past the output times and a row inside a step is its state on the step's
 * interpolant, so the steps do not depend on the output (docs/ida.md, output). While a rigid
 * contact is held, which may hold its nodes still, the steps are bounded by the loads' time
 * scale and a multiplier that turns tensile and back inside a step is found on the interpolant
 * (oe_max_step, oe_held_release). Every accepted state is a sample of
 * the run's observer, which measures it as it measures every integrator
 * (martello_observer_*, docs/run-layer.md). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ida/ida.h>
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

#define MAX_STEPS 100000000L

typedef struct {
  ode_events *E;         /* contacts, events, the observer's hand-overs (c/ode_events.c): own,
                          * or a cluster's in the local stepping (c/sundials_ode.h) */
  ode_events own;
  martello_run *run;
  /* layout of y beyond the nodes' u and v (E.iu, E.iv): the rigid contacts' P and mu */
  sunindextype N;
  sunindextype *ip, *im;
  void *mem;             /* IDA's memory: its interpolant */
  int kd, analytic;      /* the tangents' half-bandwidth; 1: the analytic Jacobian (jacobian) */
  double *kb, *cb;       /* the tangents' bands (martello_eval_tangent) */
  N_Vector yprow;        /* y' of such a row */
  char ida_msg[240];
} ida_problem;

#define fail(P, ...) oe_fail((P)->E, __VA_ARGS__)

/* ---- IDA callbacks ------------------------------------------------------------------ */

static int residual(realtype t, N_Vector yy, N_Vector yp, N_Vector rr, void *data) {
  ida_problem *P = data;
  ode_events *E = P->E;
  const double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp);
  double *res = N_VGetArrayPointer(rr);
  oe_gather(E, y, E->u, E->v);
  if (martello_eval_acceleration(E->ev, t, E->u, E->v, E->a) != MARTELLO_OK) return -1;
  int any_closed = 0;
  for (int r = 0; r < E->nr; r++) any_closed |= E->closed[r];
  if (any_closed) {
    /* M^-1 B P into fint, M^-1 B mu into fext (used here as work arrays) */
    for (int r = 0; r < E->nr; r++) E->lam[r] = y[P->ip[r]];
    oe_apply_B(E, E->lam, E->fint);
    if (martello_eval_solve_mass(E->ev, E->fint) != MARTELLO_OK) return -1;
    for (int r = 0; r < E->nr; r++) E->lam[r] = y[P->im[r]];
    oe_apply_B(E, E->lam, E->fext);
    if (martello_eval_solve_mass(E->ev, E->fext) != MARTELLO_OK) return -1;
  } else {
    memset(E->fint, 0, sizeof(double) * (size_t)E->n);
    memset(E->fext, 0, sizeof(double) * (size_t)E->n);
  }
  for (int i = 0; i < E->n; i++) {
    res[E->iu[i]] = d[E->iu[i]] - E->v[i] + E->fext[i];
    res[E->iv[i]] = d[E->iv[i]] - E->a[i] + E->fint[i];
  }
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r];
    if (E->closed[r]) {
      res[P->ip[r]] = oe_rate(E, j, E->v);
      res[P->im[r]] = oe_pen(E, j, E->u);
    } else {
      res[P->ip[r]] = y[P->ip[r]];
      res[P->im[r]] = y[P->im[r]];
    }
  }
  for (sunindextype k = 0; k < P->N; k++)
    if (!isfinite(res[k])) {
      E->nan_seen = 1;
      return 1; /* recoverable: IDA retries with a smaller step, then gives up */
    }
  return 0;
}

/* The analytic Jacobian dF/dy + c_j dF/dy' of the residual of a scene without rigid contacts
 * and with a lumped mass: c_j on the diagonal, dF_u/dv = -I, dF_v/du = M^-1 K_t,
 * dF_v/dv = M^-1 C_t over |i - k| <= kd, on the laws' branches held (martello_eval_tangent, as
 * CVODE's Jacobian in c/sundials_ode.c); fixed nodes' rows and columns of K_t and C_t are 0
 * (the evaluator holds them at u0 and at rest). One tangent evaluation instead of IDA's
 * 2 bw + 1 difference-quotient residuals. */
static int jacobian(realtype t, realtype cj, N_Vector yy, N_Vector yp, N_Vector rr, SUNMatrix J,
                    void *data, N_Vector t1, N_Vector t2, N_Vector t3) {
  ida_problem *P = data;
  ode_events *E = P->E;
  const int kd = P->kd, ld = 3 * kd + 1;
  (void)t; (void)yp; (void)rr; (void)t1; (void)t2; (void)t3;
  oe_gather(E, N_VGetArrayPointer(yy), E->u, E->v);
  if (martello_eval_tangent(E->ev, E->u, E->v, P->kb, P->cb) != MARTELLO_OK) return -1;
  const int band = SUNMatGetID(J) == SUNMATRIX_BAND;
#define JAC(r, c) (*(band ? &SM_ELEMENT_B(J, (r), (c)) : &SM_ELEMENT_D(J, (r), (c))))
  SUNMatZero(J);
  for (int i = 0; i < E->n; i++) {
    const sunindextype ru = E->iu[i], rv = E->iv[i];
    JAC(ru, ru) = cj;
    JAC(ru, rv) = -1.0;
    JAC(rv, rv) = cj;
    if (E->fixed[i]) continue;
    const double rm = 1.0 / E->mass[i];
    const int k0 = i - kd > 0 ? i - kd : 0, k1 = i + kd < E->n - 1 ? i + kd : E->n - 1;
    for (int k = k0; k <= k1; k++) {
      if (E->fixed[k]) continue;
      const size_t at = (size_t)(2 * kd + i - k) + (size_t)k * (size_t)ld;
      JAC(rv, E->iu[k]) += P->kb[at] * rm;
      JAC(rv, E->iv[k]) += P->cb[at] * rm;
    }
  }
#undef JAC
  return 0;
}

/* The roots of c/ode_events.c on the state y. */
static int roots(realtype t, N_Vector yy, N_Vector yp, realtype *g, void *data) {
  ida_problem *P = data;
  ode_events *E = P->E;
  (void)yp;
  oe_gather(E, N_VGetArrayPointer(yy), E->uq, E->vq);
  return oe_roots(E, t, E->uq, E->vq, g);
}

/* IDA's interpolant of its last step (IDAGetDky), for c/ode_events.c. */
static int interpolant(void *ctx, double t, int k, N_Vector out) {
  ida_problem *P = ctx;
  int flag = IDAGetDky(P->mem, t, k, out);
  if (flag != IDA_SUCCESS)
    return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", t, IDAGetReturnFlagName(flag));
  return MARTELLO_OK;
}

/* The degree of that interpolant: the order IDA last used (IDAGetDky answers k up to it). */
static int degree(void *ctx) {
  ida_problem *P = ctx;
  int k = 1;
  if (IDAGetLastOrder(P->mem, &k) != IDA_SUCCESS || k < 1) k = 1;
  return k;
}

static void error_handler(int code, const char *module, const char *function, char *msg,
                          void *data) {
  ida_problem *P = data;
  (void)module;
  if (code < 0) snprintf(P->ida_msg, sizeof P->ida_msg, "%s: %s", function, msg);
}

/* ---- counters, output -------------------------------------------------------------------- */

/* Add IDA's counters since the last call to the run (IDAReInit and the linear solver's
 * first call after it start them from 0 again). */
static int flush_counts(ida_problem *P, void *mem) {
  long c[9] = {0}, cf = 0, nre_ls = 0;
  int st = 0;
  st |= IDAGetNumSteps(mem, &c[MARTELLO_COUNTER_STEPS]);
  st |= IDAGetNumErrTestFails(mem, &c[MARTELLO_COUNTER_REJECTED_STEPS]);
  st |= IDAGetNumNonlinSolvConvFails(mem, &cf);
  st |= IDAGetNumNonlinSolvIters(mem, &c[MARTELLO_COUNTER_NEWTON_ITERATIONS]);
  st |= IDAGetNumResEvals(mem, &c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS]);
  st |= IDAGetNumLinResEvals(mem, &nre_ls);
  st |= IDAGetNumLinSolvSetups(mem, &c[MARTELLO_COUNTER_FACTORIZATIONS]);
  st |= IDAGetNumJacEvals(mem, &c[MARTELLO_COUNTER_JACOBIAN_EVALUATIONS]);
  st |= IDAGetNumGEvals(mem, &c[MARTELLO_COUNTER_ROOT_EVALUATIONS]);
  if (st != IDA_SUCCESS) return fail(P, MARTELLO_ERR_EXTERNAL, "IDA: could not read the counters");
  c[MARTELLO_COUNTER_REJECTED_STEPS] += cf;
  c[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS] += nre_ls;
  return oe_add_counts(P->E, c);
}

/* An accepted (committed) state y, yp at t as a sample of the observer (the force of a
 * closed rigid contact is its multiplier P_r); k: the output grid point t = k dt, or -1;
 * row: an output row on the interpolant inside a step (martello_observer_row). */
static int observe(ida_problem *P, double t, const double *y, const double *yp, int k, int row) {
  ode_events *E = P->E;
  oe_gather(E, y, E->u, E->v);
  for (int i = 0; i < E->n; i++) E->a[i] = yp[E->iv[i]];
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    E->force[j] = r >= 0 && E->closed[r] ? y[P->ip[r]] : 0.0;
  }
  return (row ? martello_observer_row : martello_observer_sample)(E->obs, E->ev, t, E->u, E->v, E->a,
                                                                  E->force, k);
}

/* An output row on the interpolant (c/ode_events.c oe_rows_inside), its y' from it too. */
static int sample(void *ctx, double t, const double *y, int k) {
  ida_problem *P = ctx;
  int st = interpolant(P, t, 1, P->yprow);
  return st == MARTELLO_OK ? observe(P, t, y, N_VGetArrayPointer(P->yprow), k, 1) : st;
}

/* Make the state at a restart consistent (c/ode_events.c), then y and y' for IDA: P the
 * multipliers of the closed set, mu = 0, v' the constrained accelerations. */
static int prepare_restart(ida_problem *P, double t, double *u, double *v, double *y, double *d) {
  ode_events *E = P->E;
  int st = oe_prepare_restart(E, t, u, v);
  if (st != MARTELLO_OK) return st;
  oe_apply_B(E, E->lam, E->x);
  if (E->nr > 0 && (st = martello_eval_solve_mass(E->ev, E->x)) != MARTELLO_OK) return fail(P, st, "IDA: singular mass");
  for (int i = 0; i < E->n; i++) {
    y[E->iu[i]] = u[i];
    y[E->iv[i]] = v[i];
    d[E->iu[i]] = v[i];
    d[E->iv[i]] = E->a[i] - (E->nr > 0 ? E->x[i] : 0.0);
  }
  for (int r = 0; r < E->nr; r++) {
    y[P->ip[r]] = E->closed[r] ? E->lam[r] : 0.0;
    y[P->im[r]] = 0.0;
    d[P->ip[r]] = 0.0;
    d[P->im[r]] = 0.0;
  }
  return MARTELLO_OK;
}

/* A reported root exactly 0 at the return (c/ode_events.c), here also the multiplier P of a
 * closed rigid contact. */
static int root_stays_zero(ida_problem *P, const double *y, const int *found) {
  ode_events *E = P->E;
  for (int r = 0; r < E->nr; r++)
    if (E->closed[r] && found[2 * E->rig_con[r]] && y[P->ip[r]] == 0.0) return 1;
  return oe_root_stays_zero(E, y, found);
}

/* ---- set-up ----------------------------------------------------------------------------- */

static void release(ida_problem *P) {
  free(P->kb);
  free(P->cb);
  free(P->ip);
  free(P->im);
  oe_release(P->E);
}

/* Half-bandwidth of the Jacobian in the interleaved layout: the node couplings are probed
 * (which accelerations change when one node's u or v does, at the initial state) and
 * completed with the contacts of the topology (penalty contacts are open at t = 0). */
static int bandwidth(ida_problem *P, const double *u0, const double *v0, sunindextype *bw) {
  ode_events *E = P->E;
  int n = E->n, st, dnode = 0;
  double *base = E->a, *pert = E->fint, *up = E->uq, *vp = E->vq;
  if ((st = martello_eval_acceleration(E->ev, 0.0, u0, v0, base)) != MARTELLO_OK) return st;
  memcpy(up, u0, sizeof(double) * (size_t)n);
  memcpy(vp, v0, sizeof(double) * (size_t)n);
  for (int k = 0; k < n; k++) {
    if (E->fixed[k]) continue;
    /* u_k and v_k together: a stiffness or a damping coupling shows either way */
    up[k] += 1e-6 * (fabs(up[k]) + 1.0);
    vp[k] += 1e-6 * (fabs(vp[k]) + 1.0);
    if ((st = martello_eval_acceleration(E->ev, 0.0, up, vp, pert)) != MARTELLO_OK) return st;
    for (int i = 0; i < n; i++)
      if (pert[i] != base[i]) dnode = abs(i - k) > dnode ? abs(i - k) : dnode;
    up[k] = u0[k];
    vp[k] = v0[k];
  }
  for (int j = 0; j < E->nc; j++) {
    if (E->rig[j] >= 0) continue;
    for (int p = E->con.first[j]; p < E->con.first[j + 1]; p++)
      for (int q = E->con.first[j]; q < E->con.first[j + 1]; q++)
        dnode = abs(E->con.node[p] - E->con.node[q]) > dnode ? abs(E->con.node[p] - E->con.node[q]) : dnode;
  }
  sunindextype b = 1;
#define WIDEN(p, q) do { sunindextype d_ = (p) > (q) ? (p) - (q) : (q) - (p); if (d_ > b) b = d_; } while (0)
  for (int i = 0; i < n; i++)
    for (int k = i - dnode; k <= i + dnode; k++) {
      if (k < 0 || k >= n) continue;
      WIDEN(E->iv[i], E->iu[k]);
      WIDEN(E->iv[i], E->iv[k]);
    }
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r];
    for (int k = E->con.first[j]; k < E->con.first[j + 1]; k++) {
      WIDEN(P->ip[r], E->iv[E->con.node[k]]);
      WIDEN(P->im[r], E->iu[E->con.node[k]]);
    }
  }
#undef WIDEN
  *bw = b;
  return MARTELLO_OK;
}

static int setup(ida_problem *P, martello_model *model, martello_run *run) {
  ode_events *E = P->E;
  double failed = 0.0;
  P->run = run;
  E->dky = interpolant;
  E->degree = degree;
  E->ctx = P;
  int st = oe_setup(E, model, run, "IDA");
  if (st != MARTELLO_OK) return st;
  E->restarts = 1;   /* IDAReInit: BDF from order 1 */
  /* IDA steps past the output times, its rows on the interpolant (docs/ida.md, output); while a
   * rigid contact is held its steps are bounded by the loads' time scale (oe_max_step) */
  E->sample = sample;
  /* IDA steps across the laws whose force is continuous at their switches, their events
   * located inside the steps (docs/sundials-ode.md, events inside the steps) */
  if ((st = oe_use_smooth(E)) != MARTELLO_OK) return st;
  P->ip = oe_take((size_t)E->nr, sizeof(sunindextype), &failed);
  P->im = oe_take((size_t)E->nr, sizeof(sunindextype), &failed);
  if (failed > 0.0) return oe_fail_memory(E, "an array of the IDA state", failed);
  /* layout: node i's (u, v), then the (P, mu) of the rigid contacts whose first node is i
   * (between the two nodes of a chain link: half-bandwidth 3, 5 with links) */
  sunindextype pos = 0;
  for (int i = 0; i < E->n; i++) {
    E->iu[i] = pos++;
    E->iv[i] = pos++;
    for (int r = 0; r < E->nr; r++) {
      int j = E->rig_con[r], first = E->n;      /* the row's smallest node */
      for (int k = E->con.first[j]; k < E->con.first[j + 1]; k++)
        first = E->con.node[k] < first ? E->con.node[k] : first;
      if (first == i) {
        P->ip[r] = pos++;
        P->im[r] = pos++;
      }
    }
  }
  P->N = pos;
  /* the analytic Jacobian where the residual is a's alone (no rigid rows) and M^-1 diagonal */
  int lumped = 0;
  if ((st = martello_eval_bandwidth(E->ev, &P->kd, &lumped)) != MARTELLO_OK)
    return fail(P, st, "IDA: could not read the evaluator");
  P->analytic = E->nr == 0 && lumped;
  if (P->analytic) {
    const size_t nb = (size_t)(3 * P->kd + 1) * (size_t)E->n;
    P->kb = oe_take(nb, sizeof(double), &failed);
    P->cb = oe_take(nb, sizeof(double), &failed);
    if (failed > 0.0) return oe_fail_memory(E, "the tangents' bands of the IDA Jacobian", failed);
  }
  return MARTELLO_OK;
}

/* ---- the run ------------------------------------------------------------------------------ */
/* IDA's first step (docs/ida.md, initial step): IDA guesses it from the first stop time,
 * which from rest with a far output makes its first-order error test fail down to h_min; so
 * at the start and at every restart: the first step h of order 1 errs by h^2 |y''|/2 per
 * component; y'' = (a, a') at the restart (a' by a
 * forward difference along the motion) and h0 = SAFETY min_i sqrt(2 w_i / |y''_i|), w_i =
 * rtol |y_i| + atol, capped at 1e-3 of t_end (not of the output interval: the steps do not
 * depend on the output). */
#define SAFETY 0.1   /* IDA's first-order error estimate is crude: a margin below it */
static int initial_step(ida_problem *P, double t, const double *u, const double *v, double *h0) {
  ode_events *E = P->E;
  const int n = E->n;
  const double cap = 1e-3 * E->t_end, d = 1e-6 * cap;
  int st = martello_eval_acceleration(E->ev, t, u, v, E->a);
  if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t);
  for (int i = 0; i < n; i++) {
    E->uq[i] = u[i] + d * v[i];
    E->vq[i] = v[i] + d * E->a[i];
  }
  st = martello_eval_acceleration(E->ev, t + d, E->uq, E->vq, E->x);
  if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t + d);
  *h0 = cap;
  for (int i = 0; i < n; i++) {
    double ju = fabs(E->a[i]), jv = fabs(E->x[i] - E->a[i]) / d;
    double wu = E->rtol * fabs(u[i]) + E->atol, wv = E->rtol * fabs(v[i]) + E->atol;
    if (ju > 0.0) *h0 = fmin(*h0, SAFETY * sqrt(2.0 * wu / ju));
    if (jv > 0.0) *h0 = fmin(*h0, SAFETY * sqrt(2.0 * wv / jv));
  }
  return MARTELLO_OK;
}

static int check(ida_problem *P, int flag, const char *call) {
  if (flag >= 0) return MARTELLO_OK;
  return fail(P, MARTELLO_ERR_EXTERNAL, "%s failed: %s", call, IDAGetReturnFlagName(flag));
}

/* The Jacobian's half-bandwidth bw at the state (u, v) and whether a band solver pays. */
static int band(ida_problem *P, const double *u0, const double *v0, sunindextype *bwp, int *banded) {
  ode_events *E = P->E;
  int st;
  /* linear solver: band in the interleaved layout when it pays (chains), dense otherwise or
   * with consistent-mass couplings (M^-1 is full) */
  sunindextype bw = P->N;
  if (E->ncoupling == 0 && P->N > 8 && (st = bandwidth(P, u0, v0, &bw)) != MARTELLO_OK)
    return fail(P, st, "IDA: force evaluation failed while probing the bandwidth");
  /* the analytic Jacobian's couplings: u_k and v_k of |i - k| <= kd in v_i's row (2 kd + 1
   * places away in the interleaved layout) */
  if (P->analytic && bw < 2 * (sunindextype)P->kd + 1) bw = 2 * (sunindextype)P->kd + 1;
  *bwp = bw;
  *banded = 2 * bw + 1 < P->N / 2;
  return MARTELLO_OK;
}

/* IDA at (0, yy, yp) with its tolerances, linear solver (band of half-width bw or dense), first
 * step from (u0, v0), algebraic rows and roots. */
static int create(ida_problem *P, SUNContext sunctx, N_Vector yy, N_Vector yp, N_Vector id, sunindextype bw,
                  int banded, const double *u0, const double *v0, SUNMatrix *Jp, SUNLinearSolver *LSp) {
  ode_events *E = P->E;
  int st;
  /* IDA: create, init, options (SUNDIALS lifecycle) */
  void *mem = IDACreate(sunctx);
  if (!mem) return oe_fail_memory(E, "the IDA solver memory (IDACreate)", -1.0);
  P->mem = mem;
  if ((st = check(P, IDASetErrHandlerFn(mem, error_handler, P), "IDASetErrHandlerFn"))) return st;
  if ((st = check(P, IDAInit(mem, residual, 0.0, yy, yp), "IDAInit"))) return st;
  /* vector tolerances: atol for u, v and P; the GGL multiplier mu is out of the Newton test.
   * mu vanishes on the exact solution and only absorbs the round-off of delta = 0, amplified
   * by c_j ~ 1/h in the index-2 Newton matrix (a node-to-node gap is zero only to ~eps|u|,
   * which gives mu ~ c_j m eps |u|): judged with atol it would fail every short step. Its
   * effect on u is tested through u itself. */
  double *av = N_VGetArrayPointer(id);
  for (sunindextype k = 0; k < P->N; k++) av[k] = E->atol;
  for (int r = 0; r < E->nr; r++) av[P->im[r]] = 1e30;
  if ((st = check(P, IDASVtolerances(mem, E->rtol, id), "IDASVtolerances"))) return st;
  if ((st = check(P, IDASetUserData(mem, P), "IDASetUserData"))) return st;
  *Jp = banded ? SUNBandMatrix(P->N, bw, bw, sunctx) : SUNDenseMatrix(P->N, P->N, sunctx);
  if (!*Jp) return oe_fail_memory(E, "the IDA Jacobian matrix", -1.0);
  *LSp = banded ? SUNLinSol_Band(yy, *Jp, sunctx) : SUNLinSol_Dense(yy, *Jp, sunctx);
  if (!*LSp) return oe_fail_memory(E, "the IDA linear solver", -1.0);
  if ((st = check(P, IDASetLinearSolver(mem, *LSp, *Jp), "IDASetLinearSolver"))) return st;
  if (P->analytic && (st = check(P, IDASetJacFn(mem, jacobian), "IDASetJacFn"))) return st;
  if ((st = check(P, IDASetMaxStep(mem, oe_max_step(E)), "IDASetMaxStep"))) return st;
  double h0;
  if ((st = initial_step(P, 0.0, u0, v0, &h0)) != MARTELLO_OK) return st;
  if ((st = check(P, IDASetInitStep(mem, h0), "IDASetInitStep"))) return st;
  double *idv = N_VGetArrayPointer(id);
  for (sunindextype k = 0; k < P->N; k++) idv[k] = 1.0;
  for (int r = 0; r < E->nr; r++) idv[P->ip[r]] = idv[P->im[r]] = 0.0;
  if ((st = check(P, IDASetId(mem, id), "IDASetId"))) return st;
  if (E->nr > 0 && (st = check(P, IDASetSuppressAlg(mem, SUNTRUE), "IDASetSuppressAlg"))) return st;
  if (oe_nroots(E) > 0) {
    if ((st = check(P, IDARootInit(mem, oe_nroots(E), roots), "IDARootInit"))) return st;
    if ((st = check(P, IDASetNoInactiveRootWarn(mem), "IDASetNoInactiveRootWarn"))) return st;
  }
  return MARTELLO_OK;
}

static int integrate(ida_problem *P, SUNContext sunctx, N_Vector yy, N_Vector yp, N_Vector id,
                     SUNMatrix *Jp, SUNLinearSolver *LSp) {
  ode_events *E = P->E;
  int st, n = E->n;
  double *u0 = E->u, *v0 = E->v;
  if ((st = martello_model_initial_state(E->model, u0, v0)) != MARTELLO_OK)
    return fail(P, st, "IDA: could not read the initial state");
  for (int i = 0; i < n; i++)
    if (E->fixed[i]) v0[i] = 0.0;

  /* linear solver: band in the interleaved layout when it pays (chains), dense otherwise */
  sunindextype bw;
  int banded;
  if ((st = band(P, u0, v0, &bw, &banded)) != MARTELLO_OK) return st;

  /* initial contact states: penalty contacts already penetrated are in a phase from t = 0
   * (the observer opens it); rigid contacts at zero gap that approach or rest are resolved as
   * impacts at t = 0 */
  if ((st = oe_initial_contacts(E, u0, v0)) != MARTELLO_OK) return st;
  if ((st = martello_observer_begin(E->obs, E->ev, u0, v0, "tighten rtol and atol")) != MARTELLO_OK)
    /* out of memory: the observer failed the run with its line */
    return st == MARTELLO_ERR_MEMORY ? st : fail(P, st, "IDA: martello_observer_begin failed");
  if ((st = prepare_restart(P, 0.0, u0, v0, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp))) != MARTELLO_OK) return st;

  if ((st = create(P, sunctx, yy, yp, id, bw, banded, u0, v0, Jp, LSp)) != MARTELLO_OK) return st;
  void *mem = P->mem;

  int k_out = 1;
  double t_out = oe_output_time(E, k_out), t_last = 0.0;
  if ((st = observe(P, 0.0, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), 0, 0)) != MARTELLO_OK) return st;
  oe_accepted(E, N_VGetArrayPointer(yy));
  /* the stops: the loads' kinks and t_end (the output rows lie on the steps' interpolant) */
  int kink = 0;
  double t_stop = oe_next_stop(E, 0.0, E->t_end, &kink);
  if ((st = check(P, IDASetStopTime(mem, t_stop), "IDASetStopTime"))) return st;
  const size_t n_found = (size_t)(oe_nroots(E) + 1);
  int *found = calloc(n_found, sizeof(int));
  if (!found) return oe_fail_memory(E, "the IDA root flags", (double)(n_found * sizeof(int)));
  long steps = 0;
  st = MARTELLO_OK;
  while (t_last < E->t_end) {
    double tret = t_last;
    int flag = IDASolve(mem, E->t_end, &tret, yy, yp, IDA_ONE_STEP);
    if (flag < 0) {
      double tcur = t_last;
      if (IDAGetCurrentTime(mem, &tcur) != IDA_SUCCESS) tcur = t_last;
      E->t_now = tcur;
      /* a state, rate or step that overflowed (an error norm of inf gives a step of 0 or
       * NaN) makes IDA blame its inputs, e.g. a stop time "behind" the current time: that
       * is a divergence, not an IDA failure */
      double hcur = 0.0;
      if (IDAGetCurrentStep(mem, &hcur) == IDA_SUCCESS && !(isfinite(hcur) && hcur != 0.0))
        E->nan_seen = 1;
      if (!isfinite(tcur)) E->nan_seen = 1;
      for (sunindextype k = 0; k < P->N; k++)
        if (!isfinite(N_VGetArrayPointer(yy)[k])) E->nan_seen = 1;
      /* an error test that fails at any step while atol is near the rounding of the state:
       * where a component crosses zero its weight rtol |y| + atol is atol alone, below what
       * the arithmetic resolves (docs/ida.md "Failures") */
      double y_max = 0.0;
      for (sunindextype k = 0; k < P->N; k++) y_max = fmax(y_max, fabs(N_VGetArrayPointer(yy)[k]));
      const char *hint = flag == IDA_ERR_FAIL && E->atol < 1e3 * DBL_EPSILON * y_max
                             ? "; atol may be below the rounding of the state where a component"
                               " crosses zero (its error weight is atol alone there): loosen"
                               " analysis.atol to at least 1e3 eps x the state's size"
                             : "";
      if (E->nan_seen)
        st = martello_observer_fail(E->obs, MARTELLO_ERR_DIVERGED, tcur, NULL);
      else
        st = fail(P, MARTELLO_ERR_EXTERNAL, "IDASolve failed at t = %.9e s: %s (%s)%s", tcur,
                  IDAGetReturnFlagName(flag), P->ida_msg, hint);
      break;
    }
    E->nan_seen = 0;
    oe_new_step(E, tret);
    if (++steps > MAX_STEPS) {
      st = fail(P, MARTELLO_ERR_NOT_CONVERGED, "IDA: more than %ld steps before t = %.9e s", MAX_STEPS, tret);
      break;
    }
    int restart = 0;
    double t_r = tret;
    if (flag == IDA_ROOT_RETURN) {
      if ((st = check(P, IDAGetRootInfo(mem, found), "IDAGetRootInfo"))) break;
      restart = oe_classify_roots(E, t_last, tret, N_VGetArrayPointer(yy), found, &t_r);
      if (restart < 0) {
        st = restart;
        break;
      }
      if (!restart) restart = root_stays_zero(P, N_VGetArrayPointer(yy), found);
    }
    /* a kink of the load (docs/ida.md, time events): IDA restarts across it */
    if (!restart && flag == IDA_TSTOP_RETURN && tret == t_stop && kink && t_stop < E->t_end) restart = 1;
    if (!restart) {
      double h_last = 0.0;
      if (IDAGetLastStep(mem, &h_last) != IDA_SUCCESS) h_last = 0.0;
      restart = oe_boundary_events(E, t_last, tret, N_VGetArrayPointer(yy), h_last, &t_r);
      if (restart < 0) {
        st = restart;
        break;
      }
    }
    /* a held contact's multiplier that turns tensile and back inside the step */
    if (!restart && (restart = oe_held_release(E, t_last, tret, N_VGetArrayPointer(yy), &t_r)) < 0) {
      st = restart;
      break;
    }
    if (restart && t_r < tret) {
      int f0 = IDAGetDky(mem, t_r, 0, yy), f1 = IDAGetDky(mem, t_r, 1, yp);
      if ((st = check(P, f0 < 0 ? f0 : f1, "IDAGetDky"))) break;
    }
    if ((st = oe_rows_inside(E, &t_last, t_r, &k_out, &t_out)) != MARTELLO_OK) break;
    if ((st = oe_inner_events(E, t_last, t_r, N_VGetArrayPointer(yy))) != MARTELLO_OK) break;
    if ((st = oe_stretch(E, t_last, t_r, N_VGetArrayPointer(yy), restart)) != MARTELLO_OK) break;
    oe_keep_end_rates(E, !restart);
    t_last = t_r;
    E->t_now = t_r;
    const double *y = N_VGetArrayPointer(yy);
    oe_gather(E, y, E->u, E->v);
    if (restart) {
      if ((st = oe_restart_progress(E, t_r)) != MARTELLO_OK) break;
      if ((st = flush_counts(P, mem)) != MARTELLO_OK) break;
      if ((st = prepare_restart(P, t_r, E->u, E->v, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp))) != MARTELLO_OK) break;
    } else {
      if ((st = oe_commit(E, E->u, E->v)) != MARTELLO_OK) {
        st = fail(P, st, "IDA: commit failed");
        break;
      }
      if ((st = oe_hand_work(E)) != MARTELLO_OK) break;
    }
    /* an output time reached (tstop), or passed within round-off by a restart: grid point
     * k_out·every of the output interval dt (the observer records it) */
    int at_output = t_r == t_out || (restart && t_out - t_r <= 16.0 * DBL_EPSILON * t_out);
    if ((st = observe(P, t_r, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp),
                      at_output ? k_out * E->every : -1, 0)) != MARTELLO_OK)
      break;
    oe_accepted(E, N_VGetArrayPointer(yy));   /* after a restart's jumps */
    if (at_output) {
      if (t_out >= E->t_end) {
        t_last = E->t_end;
        break;
      }
      t_out = oe_output_time(E, ++k_out);
    }
    if (restart) {
      double h0;
      oe_gather(E, N_VGetArrayPointer(yy), E->u, E->v);
      if ((st = initial_step(P, t_r, E->u, E->v, &h0)) != MARTELLO_OK) break;
      if ((st = check(P, IDASetInitStep(mem, h0), "IDASetInitStep"))) break;
      if ((st = check(P, IDAReInit(mem, t_r, yy, yp), "IDAReInit"))) break;
      /* the held set may have changed: its bound on the steps with it (0: none) */
      if ((st = check(P, IDASetMaxStep(mem, oe_max_step(E)), "IDASetMaxStep"))) break;
      memset(E->cnt_last, 0, sizeof E->cnt_last);   /* IDAReInit starts the counters again */
    }
    if (restart || at_output || tret >= t_stop) {
      t_stop = oe_next_stop(E, t_r, E->t_end, &kink);
      if ((st = check(P, IDASetStopTime(mem, t_stop), "IDASetStopTime"))) break;
    }
  }
  free(found);
  int st2 = flush_counts(P, mem);
  if (st == MARTELLO_OK) st = st2;
  if (st == MARTELLO_OK) st = martello_observer_finish(E->obs, t_last);
  return st;
}

int martello_ida_run(martello_model *model, martello_run *run) {
  martello_settings s;
  if (model && run && martello_run_settings(run, &s) == MARTELLO_OK && s.local_stepping)
    return martello_ode_local_run(model, run);
  ida_problem prob;
  ida_problem *P = &prob;
  memset(P, 0, sizeof *P);
  ode_events *E = P->E = &P->own;
  if (!model || !run) return MARTELLO_ERR_ARGUMENT;
  int st = martello_run_observer(run, &E->obs);
  if (st != MARTELLO_OK) return st;
  st = setup(P, model, run);
  SUNContext sunctx = NULL;
  N_Vector yy = NULL, yp = NULL, id = NULL;
  SUNMatrix J = NULL;
  SUNLinearSolver LS = NULL;
  if (st == MARTELLO_OK && SUNContext_Create(NULL, &sunctx) != 0)
    st = fail(P, MARTELLO_ERR_EXTERNAL, "SUNContext_Create failed");
  if (st == MARTELLO_OK) {
    yy = N_VNew_Serial(P->N, sunctx);
    yp = N_VNew_Serial(P->N, sunctx);
    id = N_VNew_Serial(P->N, sunctx);
    E->ytmp = N_VNew_Serial(P->N, sunctx);
    E->ytd = N_VNew_Serial(P->N, sunctx);
    E->yrow = N_VNew_Serial(P->N, sunctx);
    P->yprow = N_VNew_Serial(P->N, sunctx);
    if (!yy || !yp || !id || !E->ytmp || !E->ytd || !E->yrow || !P->yprow)
      st = oe_fail_memory(E, "the IDA state vectors", -1.0);
  }
  /* a failed run keeps what it computed (the observer closed its open phases) */
  if (st == MARTELLO_OK) st = integrate(P, sunctx, yy, yp, id, &J, &LS);
  if (P->mem) IDAFree(&P->mem);
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  if (yy) N_VDestroy(yy);
  if (yp) N_VDestroy(yp);
  if (id) N_VDestroy(id);
  if (E->ytmp) N_VDestroy(E->ytmp);
  if (E->ytd) N_VDestroy(E->ytd);
  if (E->yrow) N_VDestroy(E->yrow);
  if (P->yprow) N_VDestroy(P->yprow);
  if (sunctx) SUNContext_Free(&sunctx);
  release(P);
  return st;
}

/* ---- the pieces c/local_stepping.c drives per cluster (c/sundials_ode.h) ----------------------
 * IDA on a cluster's sub-model, its events those of the cluster's ode_problem (P->E): the same
 * residual, Jacobian, roots, first step and restarts as the global run above (docs/ida.md). The
 * local stepping has no rigid contacts, so y = [u_i, v_i] node by node as in CVODE's layout. */

typedef struct {
  ida_problem I;
  void *ctx;
  N_Vector yp, id;
  double *yp0;    /* y' made consistent by a restart before IDA has its vectors (create) */
} ida_seam;

static ida_seam *seam(ode_problem *P) { return P->ida; }

int ida_seam_setup(ode_problem *P, martello_model *model, martello_run *run) {
  ida_seam *S = calloc(1, sizeof *S);
  if (!S) return oe_fail_memory(&P->E, "the IDA problem of a cluster", (double)sizeof *S);
  P->ida = S;
  S->I.E = &P->E;
  P->name = "IDA";
  P->E.name = P->name;
  int st = setup(&S->I, model, run);
  if (st != MARTELLO_OK) return st;
  P->N = S->I.N;
  P->kd = S->I.kd;
  S->yp0 = calloc((size_t)P->N, sizeof(double));
  return S->yp0 ? MARTELLO_OK : oe_fail_memory(&P->E, "the IDA state of a cluster", (double)P->N * sizeof(double));
}

void ida_seam_release(ode_problem *P) {
  ida_seam *S = seam(P);
  if (!S) return;
  if (S->I.mem) IDAFree(&S->I.mem);
  if (S->yp) N_VDestroy(S->yp);
  if (S->id) N_VDestroy(S->id);
  if (S->I.yprow) N_VDestroy(S->I.yprow);
  free(S->I.kb);
  free(S->I.cb);
  free(S->I.ip);
  free(S->I.im);
  free(S->yp0);
  free(S);
  P->ida = NULL;
}

/* The state y at a restart at t made consistent, y' with it (prepare_restart). */
int ida_seam_prepare_restart(ode_problem *P, double t, double *y) {
  ida_seam *S = seam(P);
  ode_events *E = &P->E;
  oe_gather(E, y, E->u, E->v);
  double *d = S->yp ? N_VGetArrayPointer(S->yp) : S->yp0;
  return prepare_restart(&S->I, t, E->u, E->v, y, d);
}

static int seam_first_step(ida_seam *S, double t, N_Vector y) {
  ode_events *E = S->I.E;
  double h0;
  oe_gather(E, N_VGetArrayPointer(y), E->u, E->v);
  int st = initial_step(&S->I, t, E->u, E->v, &h0);
  return st != MARTELLO_OK ? st : check(&S->I, IDASetInitStep(S->I.mem, h0), "IDASetInitStep");
}

/* IDA at (0, y, y') with the global run's options (integrate above). */
int ida_seam_create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *Jp, SUNLinearSolver *LSp) {
  ida_seam *S = seam(P);
  ida_problem *I = &S->I;
  ode_events *E = &P->E;
  int st, banded;
  sunindextype bw;
  S->yp = N_VNew_Serial(I->N, ctx);
  S->id = N_VNew_Serial(I->N, ctx);
  I->yprow = N_VNew_Serial(I->N, ctx);
  if (!S->yp || !S->id || !I->yprow) return oe_fail_memory(E, "the IDA state vectors of a cluster", -1.0);
  memcpy(N_VGetArrayPointer(S->yp), S->yp0, sizeof(double) * (size_t)I->N);
  oe_gather(E, N_VGetArrayPointer(y), E->u, E->v);
  if ((st = band(I, E->u, E->v, &bw, &banded)) != MARTELLO_OK) return st;
  return create(I, ctx, y, S->yp, S->id, bw, banded, E->u, E->v, Jp, LSp);
}

/* A restart at (t, y) with the y' of ida_seam_prepare_restart, its first step as the global
 * run's (initial_step). */
int ida_seam_restart(ode_problem *P, double t, N_Vector y) {
  ida_seam *S = seam(P);
  int st;
  if ((st = seam_first_step(S, t, y)) != MARTELLO_OK) return st;
  if ((st = check(&S->I, IDAReInit(S->I.mem, t, y, S->yp), "IDAReInit"))) return st;
  memset(P->E.cnt_last, 0, sizeof P->E.cnt_last);   /* IDAReInit starts the counters again */
  return check(&S->I, IDASetMaxStep(S->I.mem, oe_max_step(&P->E)), "IDASetMaxStep");
}

int ida_seam_flush_counts(ode_problem *P) { return flush_counts(&seam(P)->I, seam(P)->I.mem); }
int ida_seam_check(ode_problem *P, int flag, const char *call) { return check(&seam(P)->I, flag, call); }
int ida_seam_root_stays_zero(ode_problem *P, const double *y, const int *found) {
  return root_stays_zero(&seam(P)->I, y, found);
}
int ida_seam_interpolant(ode_problem *P, double t, int k, N_Vector out) {
  return interpolant(&seam(P)->I, t, k, out);
}
double ida_seam_last_step(ode_problem *P) {
  double h = 0.0;
  if (IDAGetLastStep(seam(P)->I.mem, &h) != IDA_SUCCESS) h = 0.0;
  return h;
}
int ida_seam_step(ode_problem *P, double tout, N_Vector y, double *tret) {
  int flag = IDASolve(seam(P)->I.mem, tout, tret, y, seam(P)->yp, IDA_ONE_STEP);
  if (flag < 0) return flag;
  if (flag == IDA_ROOT_RETURN) return ODE_STEP_ROOT;
  return flag == IDA_TSTOP_RETURN ? ODE_STEP_TSTOP : ODE_STEP_DONE;
}
int ida_seam_root_info(ode_problem *P, int *found) {
  return check(&seam(P)->I, IDAGetRootInfo(seam(P)->I.mem, found), "IDAGetRootInfo");
}
int ida_seam_stop(ode_problem *P, double t) {
  return check(&seam(P)->I, IDASetStopTime(seam(P)->I.mem, t), "IDASetStopTime");
}
double ida_seam_current_time(ode_problem *P, double t_last) {
  double t = t_last;
  if (IDAGetCurrentTime(seam(P)->I.mem, &t) != IDA_SUCCESS) t = t_last;
  return t;
}
const char *ida_seam_flag(ode_problem *P, int flag) { (void)P; return IDAGetReturnFlagName(flag); }
