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
 * Events are roots of IDA (IDARootInit), two per contact: delta_j and its rate for open
 * contacts and penalty contacts (the rate root stops at every extremum of the gap, which
 * gives the exact peak penetration and catches a contact that opens and closes inside one
 * step), P_r for closed rigid contacts (release when it turns tensile). At an onset or a
 * separation of a penalty contact, an impact (Newton's law with restitution e, all contacts
 * at zero gap at once: an impulse-level LCP), a closing (e = 0, or an accumulation of
 * impacts: the policy of docs/impulse.md §4) or a release, the state is made consistent and IDA restarts there (IDAReInit) instead of
 * stepping across the kink. Steps are taken in IDA_ONE_STEP mode so that path-dependent
 * links commit at every accepted step; output times are stop times (IDASetStopTime), so
 * every history row is an accepted, committed state. Every accepted state is a sample of
 * the run's observer, which measures it as it measures every integrator
 * (martello_observer_*, docs/run-layer.md). */
#include <float.h>
#include <math.h>
#include <stdarg.h>
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

/* What happens to a contact at a restart. */
enum { ACT_NONE, ACT_ONSET, ACT_SEPARATION, ACT_IMPACT, ACT_RELEASE };

/* Position tolerance of a rigid contact, in units of IDA's own: a rigid contact within it
 * of zero gap touches (it enters the impact LCP with the one whose root fired, and a rebound
 * that would not leave it has accumulated). IDA's position error is a small multiple of its
 * local tolerance rtol |u| + atol. */
#define POSITION_TOL_FACTOR 10.0
#define MAX_STEPS 100000000L

typedef struct {
  martello_model *model;
  martello_run *run;
  martello_observer *obs; /* what the run measures */
  martello_eval *ev;
  /* scene (martello_model_topology) */
  int n, nc, nr, ncoupling;
  double *mass, *gap, *rest;
  int *fixed, *con_a, *con_b, *scheme;
  int *rig;      /* contact -> rigid index, or -1 (penalty) */
  int *rig_con;  /* rigid index -> contact */
  /* layout of y */
  sunindextype N;
  sunindextype *iu, *iv, *ip, *im;
  /* modes */
  int *closed;   /* per rigid contact: constraint active */
  int *act;      /* per contact: ACT_* at the restart being prepared */
  int *opened;   /* per rigid contact: opened by the multiplier check at this restart */
  int *was_closed, *hit, *cand; /* per rigid contact, at an impact */
  double *w_in, *w_out; /* per contact: approach and rebound speed of the impact being resolved */
  /* work */
  double *u, *v, *a, *x, *uq, *vq, *fint, *fext, *force, *lam;
  double *S, *rhs, *mb;
  int *aset;
  double *q, *w0;
  /* the impulse problem (c/martello_internal.h): M^-1 B_r^T of every rigid contact (column r,
   * B_r = e_b - e_a), built once; the door lists of the contacts in aset */
  double *cols;
  int cols_ready, *dc;
  /* the switches of the laws' branches (martello_eval_switches), refreshed at every commit:
   * roots 2 nc .. 2 nc + nsw - 1 */
  int nsw, *sw_a, *sw_b;
  double *sw_al, *sw_be, *sw_ga;
  martello_accumulation acc; /* the accumulation rule's phases (c/accumulation.c) */
  /* the release roots: the closed set at the last restart (its rigid contacts lc[0..mc), their
   * door list dlc and W factored in Wc), the free accelerations ar and the signed multipliers
   * lr of a state, and the tension each needs before it counts (lamtol, per rigid contact) */
  int mc, *lc, *dlc;
  double *Wc, *ar, *lr, *lamtol;
  double *v_last;             /* node velocities at the last accepted state (located extrema) */
  /* located peaks (c/located_peaks.c): element quantities and rates (the layout of
   * c/located_peaks.c's packed layout) at the ends of the stretch (0, 1)
   * and at a probe (c); node v, a and jerk at both ends; the step's interpolant */
  int nl, start_rates;
  double *el0, *el1, *elc, *pv0, *pa0, *pj0, *pv1, *pa1, *pj1, *ua, *va, *aa;
  void *mem_now;
  N_Vector ytd;
  /* settings */
  double rtol, atol, event_tol, t_end, h_max, out_dt, dt;
  int every;     /* output intervals dt per stop time out_dt */
  /* works since the last hand-over to the observer: external, internal, of the links other
   * than dampers and of the penalty contacts (quadrature), kinetic energy taken out at
   * restarts */
  double dw_ext, dw_int, dw_links, dw_contact, e_impact;
  /* diagnostics */
  double t_now;  /* where the integration stands (the t_reached of a failure) */
  int nan_seen;
  char ida_msg[240];
  long long events;
  long cnt_last[9];
} ida_problem;

/* ---- small helpers ------------------------------------------------------------------ */

static int fail_memory(ida_problem *P, const char *what, double bytes);

/* The run fails with code at P->t_now, saying fmt; MARTELLO_ERR_MEMORY comes only from the
 * impulse doors (their LCP solver's work arrays) and says so in the out-of-memory line. */
static int fail(ida_problem *P, int code, const char *fmt, ...) {
  char buf[480];
  va_list ap;
  if (code == MARTELLO_ERR_MEMORY)
    return fail_memory(P, "the work arrays of the IDA LCP solver", -1.0);
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return martello_observer_fail(P->obs, code, P->t_now, buf);
}


static double node_u(int i, const double *u) { return i < 0 ? 0.0 : u[i]; }

/* delta = (u_a - u_b) - gap, in the kernels' order of operations (fortran/evaluator.f90). */
static double penetration(const ida_problem *P, int j, const double *u) {
  return (node_u(P->con_a[j], u) - node_u(P->con_b[j], u)) - P->gap[j];
}

static double pen_rate(const ida_problem *P, int j, const double *v) {
  return node_u(P->con_a[j], v) - node_u(P->con_b[j], v);
}

static void gather(const ida_problem *P, const double *y, double *u, double *v) {
  for (int i = 0; i < P->n; i++) {
    u[i] = y[P->iu[i]];
    v[i] = y[P->iv[i]];
  }
}

/* x <- B lambda over the closed rigid contacts (x has length n). */
static void apply_B(const ida_problem *P, const double *lam, double *x) {
  memset(x, 0, sizeof(double) * (size_t)P->n);
  for (int r = 0; r < P->nr; r++) {
    if (!P->closed[r] || lam[r] == 0.0) continue;
    int j = P->rig_con[r];
    if (P->con_a[j] >= 0) x[P->con_a[j]] += lam[r];
    if (P->con_b[j] >= 0) x[P->con_b[j]] -= lam[r];
  }
}

static double dot_B(const ida_problem *P, int j, const double *x) { return pen_rate(P, j, x); }

/* Gap within which a rigid contact touches (see POSITION_TOL_FACTOR). */
static double position_tol(const ida_problem *P, int j, const double *u) {
  double s = fabs(P->gap[j]);
  s = fmax(s, fabs(node_u(P->con_a[j], u)));
  s = fmax(s, fabs(node_u(P->con_b[j], u)));
  return POSITION_TOL_FACTOR * (P->rtol * s + P->atol);
}

static double speed_tol(const ida_problem *P, const double *v) {
  double vm = 0.0;
  for (int i = 0; i < P->n; i++) vm = fmax(vm, fabs(v[i]));
  return 64.0 * DBL_EPSILON * vm + DBL_MIN;
}

/* Move contact j strictly to side sgn (+1: delta > 0, -1: delta < 0) by the smallest shift of
 * one free node: the kernels decide a penalty law's regime by the sign of delta, so a restart
 * exactly at delta = 0 would not know on which side it is. */
static void nudge(ida_problem *P, int j, int sgn, double *u) {
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

/* M^-1 B_r^T of every rigid contact, once (the mass matrix does not change). */
static int impulse_columns(ida_problem *P) {
  if (P->cols_ready) return MARTELLO_OK;
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r], st;
    double *c = P->cols + (size_t)r * (size_t)P->n;
    memset(c, 0, sizeof(double) * (size_t)P->n);
    if (P->con_a[j] >= 0) c[P->con_a[j]] -= 1.0;
    if (P->con_b[j] >= 0) c[P->con_b[j]] += 1.0;
    if ((st = martello_eval_solve_mass(P->ev, c)) != MARTELLO_OK) return st;
  }
  P->cols_ready = 1;
  return MARTELLO_OK;
}

/* The rigid contacts aset[0..m) as the impulse door's list (contact indices) into dc. */
static void door_list(ida_problem *P, int m) {
  for (int k = 0; k < m; k++) P->dc[k] = P->rig_con[P->aset[k]];
}

/* The impulse door's topology arguments (c/martello_internal.h): sides, columns in cols. */
#define TOPOLOGY(P) (P)->con_a, (P)->con_b, (P)->rig, (P)->cols

static int closed_set(ida_problem *P) {
  int m = 0;
  for (int r = 0; r < P->nr; r++)
    if (P->closed[r]) P->aset[m++] = r;
  return m;
}

/* ---- IDA callbacks ------------------------------------------------------------------ */

static int residual(realtype t, N_Vector yy, N_Vector yp, N_Vector rr, void *data) {
  ida_problem *P = data;
  const double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp);
  double *res = N_VGetArrayPointer(rr);
  gather(P, y, P->u, P->v);
  if (martello_eval_acceleration(P->ev, t, P->u, P->v, P->a) != MARTELLO_OK) return -1;
  int any_closed = 0;
  for (int r = 0; r < P->nr; r++) any_closed |= P->closed[r];
  if (any_closed) {
    /* M^-1 B P into fint, M^-1 B mu into fext (used here as work arrays) */
    for (int r = 0; r < P->nr; r++) P->lam[r] = y[P->ip[r]];
    apply_B(P, P->lam, P->fint);
    if (martello_eval_solve_mass(P->ev, P->fint) != MARTELLO_OK) return -1;
    for (int r = 0; r < P->nr; r++) P->lam[r] = y[P->im[r]];
    apply_B(P, P->lam, P->fext);
    if (martello_eval_solve_mass(P->ev, P->fext) != MARTELLO_OK) return -1;
  } else {
    memset(P->fint, 0, sizeof(double) * (size_t)P->n);
    memset(P->fext, 0, sizeof(double) * (size_t)P->n);
  }
  for (int i = 0; i < P->n; i++) {
    res[P->iu[i]] = d[P->iu[i]] - P->v[i] + P->fext[i];
    res[P->iv[i]] = d[P->iv[i]] - P->a[i] + P->fint[i];
  }
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r];
    if (P->closed[r]) {
      res[P->ip[r]] = pen_rate(P, j, P->v);
      res[P->im[r]] = penetration(P, j, P->u);
    } else {
      res[P->ip[r]] = y[P->ip[r]];
      res[P->im[r]] = y[P->im[r]];
    }
  }
  for (sunindextype k = 0; k < P->N; k++)
    if (!isfinite(res[k])) {
      P->nan_seen = 1;
      return 1; /* recoverable: IDA retries with a smaller step, then gives up */
    }
  return 0;
}

/* Commit (u, v) in the evaluator; the laws' branches may change there, so the switches are
 * read again. */
static int commit(ida_problem *P, const double *u, const double *v) {
  int st = martello_eval_commit(P->ev, u, v);
  if (st == MARTELLO_OK && P->nsw > 0)
    st = martello_eval_switches(P->ev, P->sw_a, P->sw_b, P->sw_al, P->sw_be, P->sw_ga);
  return st;
}

/* The signed multipliers of the closed set at (t, u, v) into P->lr (per rigid contact,
 * compression > 0): the bilateral contact forces W_H lambda = -B_H a_free of the set closed at
 * the last restart, from the state itself. IDA's own multiplier P, an index-2 algebraic
 * variable out of the error test, is not accurate between the steps' ends: while a contact
 * holds a node still, IDA's steps grow to the output interval and the root of its interpolated
 * P fell up to 8e-3 s from the release (P9 at rtol 1e-11), at a time that moved with the
 * output interval. */
static int closed_multipliers(ida_problem *P, double t, const double *u, const double *v) {
  int st = martello_eval_acceleration(P->ev, t, u, v, P->ar);
  if (st == MARTELLO_OK)
    st = martello_impulse_project(P->n, P->mc, P->dlc, TOPOLOGY(P), P->Wc, NULL, P->ar, P->x);
  for (int k = 0; k < P->mc; k++) P->lr[P->lc[k]] = P->x[k];
  return st;
}

/* The release roots from the restart on: the closed set, W_H factored, and each contact's
 * tension bar, the rounding of the forces at its nodes (as on the event-driven integrator). */
static int closed_set_roots(ida_problem *P, const double *u, const double *v) {
  P->mc = 0;
  for (int r = 0; r < P->nr; r++)
    if (P->closed[r]) {
      int j = P->rig_con[r], a = P->con_a[j], b = P->con_b[j];
      double fs = fabs(P->lam[r]);
      if (a >= 0) fs += P->mass[a] * fabs(P->a[a]);
      if (b >= 0) fs += P->mass[b] * fabs(P->a[b]);
      P->lamtol[r] = 1e3 * DBL_EPSILON * fs;
      P->lc[P->mc] = r;
      P->dlc[P->mc++] = j;
    }
  (void)u;
  (void)v;
  if (P->mc == 0) return MARTELLO_OK;
  return martello_impulse_factor(P->n, P->mc, P->dlc, TOPOLOGY(P), P->Wc);
}

/* Two root functions per contact: (delta, delta') while open or penalty, (lambda + its
 * tension bar, 1) while a rigid contact is closed (lambda of the state, closed_multipliers);
 * then one per switch slot of the laws' branches (g > 0: the branch is left; an unused slot
 * stays at -1). */
static int roots(realtype t, N_Vector yy, N_Vector yp, realtype *g, void *data) {
  ida_problem *P = data;
  const double *y = N_VGetArrayPointer(yy);
  (void)yp;
  gather(P, y, P->uq, P->vq);
  if (P->mc > 0 && closed_multipliers(P, t, P->uq, P->vq) != MARTELLO_OK) return -1;
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j];
    if (r >= 0 && P->closed[r]) {
      g[2 * j] = P->lr[r] + P->lamtol[r];
      g[2 * j + 1] = 1.0;
    } else {
      g[2 * j] = penetration(P, j, P->uq);
      g[2 * j + 1] = pen_rate(P, j, P->vq);
    }
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
  ida_problem *P = data;
  (void)module;
  if (code < 0) snprintf(P->ida_msg, sizeof P->ida_msg, "%s: %s", function, msg);
}

/* ---- counters, energy, output -------------------------------------------------------- */

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
  long long inc[MARTELLO_NCOUNTERS] = {0};
  for (int k = 0; k < 9; k++) {
    if (k == MARTELLO_COUNTER_EVENTS || k == MARTELLO_COUNTER_CONTACT_CHATTER_RESOLUTIONS) continue;
    long d = c[k] >= P->cnt_last[k] ? c[k] - P->cnt_last[k] : c[k];
    inc[k] = d;
    P->cnt_last[k] = c[k];
  }
  inc[MARTELLO_COUNTER_EVENTS] = P->events;
  P->events = 0;
  return martello_observer_add_counts(P->obs, inc);
}

static void reset_count_baseline(ida_problem *P) {
  for (int k = 0; k < 9; k++) P->cnt_last[k] = 0;
}

/* Hand the works since the last hand-over to the observer (once per commit). */
static int hand_work(ida_problem *P) {
  int st = martello_observer_work(P->obs, P->dw_ext, P->dw_int, P->dw_links, P->dw_contact,
                                  P->e_impact);
  P->dw_ext = P->dw_int = P->dw_links = P->dw_contact = P->e_impact = 0.0;
  return st == MARTELLO_OK ? st : fail(P, st, "IDA: could not hand the works to the observer");
}

/* An accepted (committed) state y, yp at t as a sample of the observer (the force of a
 * closed rigid contact is its multiplier P_r); k: the output grid point t = k dt, or -1. */
static int observe(ida_problem *P, double t, const double *y, const double *yp, int k) {
  gather(P, y, P->u, P->v);
  for (int i = 0; i < P->n; i++) P->a[i] = yp[P->iv[i]];
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j];
    P->force[j] = r >= 0 && P->closed[r] ? y[P->ip[r]] : 0.0;
  }
  return martello_observer_sample(P->obs, P->ev, t, P->u, P->v, P->a, P->force, k);
}

/* Work of the external and internal forces (and of the links other than dampers and of the
 * penalty contacts) over [t0, t1] on the step's interpolant, 3-point Gauss-Legendre (order
 * 6), with the link states committed at t0 (as IDA's residuals saw them). */
static int work_quadrature(ida_problem *P, void *mem, double t0, double t1, N_Vector ytmp) {
  static const double xg[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  if (!(t1 > t0)) return MARTELLO_OK;
  double h = t1 - t0, we = 0.0, wi = 0.0, wl = 0.0, wc = 0.0, power[5];
  for (int k = 0; k < 3; k++) {
    double tk = t0 + 0.5 * h * (1.0 + xg[k]);
    int flag = IDAGetDky(mem, tk, 0, ytmp);
    if (flag != IDA_SUCCESS)
      return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", tk,
                  IDAGetReturnFlagName(flag));
    gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
    int st = martello_eval_forces(P->ev, tk, P->uq, P->vq, P->fint, P->fext);
    if (st == MARTELLO_OK) st = martello_eval_power(P->ev, power);
    if (st != MARTELLO_OK) return fail(P, st, "IDA: force evaluation failed at t = %.9e s", tk);
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

/* ---- contact events ------------------------------------------------------------------- */

/* Newton's impact law on the rigid contacts that touch (closed, flagged ACT_IMPACT, or open
 * at zero gap within the position tolerance), all at once (martello_impulse_newton:
 * simultaneous impacts in a chain), restitution e (0 for a closed contact). P->hit and
 * P->w_in say which contacts took an impulse and their approach speed. Then the closing
 * rule (the accumulation policy) and, for the closed set, zero rates and positions. */
static int project_closed(ida_problem *P, double t, double *u, double *v);

static int rigid_impacts(ida_problem *P, double t, double *u, double *v) {
  int st, m = 0, piv;
  if ((st = impulse_columns(P)) != MARTELLO_OK) return fail(P, st, "IDA: singular mass at an impact");
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r];
    P->hit[r] = 0;
    /* a contact released here leaves at rest: it takes no impulse (its rounding-level rate
     * made a spurious impact at 1e-35 m/s on P9 when the release fell on an output time) */
    P->cand[r] = P->closed[r] || P->act[j] == ACT_IMPACT ||
                 (P->act[j] != ACT_RELEASE && penetration(P, j, u) >= -position_tol(P, j, u));
    if (P->cand[r]) P->aset[m++] = r;
  }
  if (m > 0) {
    door_list(P, m);
    for (int k = 0; k < m; k++) {
      int r = P->aset[k], j = P->rig_con[r];
      P->w0[k] = pen_rate(P, j, v);
      P->q[k] = P->closed[r] ? 0.0 : (P->rest[j] >= 0.0 ? P->rest[j] : 0.0);
    }
    st = martello_impulse_newton(P->n, m, P->dc, TOPOLOGY(P), P->q, v, P->rhs, &piv);
    if (st != MARTELLO_OK)
      return fail(P, st, "IDA: the impact LCP of %d contacts failed at t = %.9e s (%s)", m, t,
                  st == MARTELLO_ERR_SINGULAR ? "redundant contacts" : "pivot limit");
    for (int k = 0; k < m; k++) {
      int r = P->aset[k], j = P->rig_con[r];
      if (P->rhs[k] > 0.0 && !P->closed[r]) {
        P->hit[r] = 1;
        P->w_in[j] = P->w0[k];
        P->w_out[j] = pen_rate(P, j, v);
        if (P->act[j] != ACT_IMPACT) P->events++;
      }
    }
    /* a closed contact that the impact sets apart (p = 0, separating) opens */
    double vtol = speed_tol(P, v);
    for (int r = 0; r < P->nr; r++)
      if (P->closed[r] && pen_rate(P, P->rig_con[r], v) < -vtol) {
        P->closed[r] = 0;
        P->opened[r] = 1;
      }
  }
  /* closing: the accumulation rule (docs/impulse.md §4) with IDA's resolutions (event_tol,
   * the position tolerance of the contact and the like one of its rate), and the normal
   * acceleration a_n that presses each contact that took an impulse with the contacts already
   * closed enforced (their forces from the persistent-contact rule): aset = [closed set,
   * candidates]. The phase of a contact closed here starts at its accumulation point. */
  int mc = closed_set(P), ma = mc;
  for (int r = 0; r < P->nr; r++)
    if (!P->closed[r] && (P->hit[r] || P->act[P->rig_con[r]] == ACT_IMPACT)) P->aset[ma++] = r;
  if (ma > mc) {
    st = martello_eval_acceleration(P->ev, t, u, v, P->a);
    if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t);
    door_list(P, ma);
    st = martello_impulse_delassus(P->n, ma, P->dc, TOPOLOGY(P), P->S);
    if (st == MARTELLO_OK && mc > 0)
      st = martello_impulse_contact_forces(P->n, mc, P->dc, TOPOLOGY(P), P->a, P->w0,
                                           P->cand, &piv);
    if (st != MARTELLO_OK)
      return fail(P, st, "IDA: the contact forces of the closed contacts failed at t = %.9e s", t);
  }
  for (int k = mc; k < ma; k++) {
    int r = P->aset[k], j = P->rig_con[r];
    double an = dot_B(P, j, P->a), rebound = fmax(-pen_rate(P, j, v), 0.0);
    double e = P->rest[j] >= 0.0 ? P->rest[j] : 0.0;
    double v_res = POSITION_TOL_FACTOR *
                   (P->rtol * (fabs(node_u(P->con_a[j], v)) + fabs(node_u(P->con_b[j], v))) + P->atol);
    double da = 0.0;
    for (int l = 0; l < mc; l++) an -= P->S[k + ma * l] * P->w0[l];
    if (rebound > 0.0 && an > 0.0) {
      /* the change of a_n over the next flight tau = 2 s/a_n, at the end of a tangent step of
       * length tau (the closed contacts' forces held) */
      const double tau = 2.0 * rebound / an;
      for (int i = 0; i < P->n; i++) {
        P->uq[i] = u[i] + tau * v[i];
        P->vq[i] = v[i] + tau * P->a[i];
      }
      st = martello_eval_acceleration(P->ev, t + tau, P->uq, P->vq, P->x);
      if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t + tau);
      da = dot_B(P, j, P->x) - dot_B(P, j, P->a);
    }
    /* tentative: rigid_multipliers opens it again if its multiplier is not compressive. A
     * contact that nothing presses (a_n <= 0) stays open, as on the event-driven integrator:
     * bodies that move on together after a plastic impact are not in a persistent contact */
    if (an > 0.0 && martello_accumulation_decide(&P->acc, j, e, rebound, an, da, t,
                                                 P->event_tol, position_tol(P, j, u), v_res, 1))
      P->closed[r] = 1;
  }
  return project_closed(P, t, u, v);
}

/* Zero the rates of the closed set (for an accumulation this removes the rest of the
 * bounces: their energy goes to E_IMPACT), then put it on delta = 0 (B u = -gap) by the
 * mass-weighted projection: at every restart, so that IDA starts on the constraints. */
static int project_closed(ida_problem *P, double t, double *u, double *v) {
  int st, m = closed_set(P);
  if (m == 0) return MARTELLO_OK;
  door_list(P, m);
  if ((st = martello_impulse_factor(P->n, m, P->dc, TOPOLOGY(P), P->S)) != MARTELLO_OK)
    return fail(P, MARTELLO_ERR_SINGULAR, "IDA: redundant closed contacts at t = %.9e s (B^T M^-1 B singular)", t);
  for (int k = 0; k < m; k++) P->q[k] = -P->gap[P->rig_con[P->aset[k]]];
  st = martello_impulse_project(P->n, m, P->dc, TOPOLOGY(P), P->S, NULL, v, P->rhs);
  if (st == MARTELLO_OK)
    st = martello_impulse_project(P->n, m, P->dc, TOPOLOGY(P), P->S, P->q, u, P->rhs);
  if (st != MARTELLO_OK) return fail(P, st, "IDA: the constraint projection failed at t = %.9e s", t);
  return MARTELLO_OK;
}

/* Multipliers of the closed set: the persistent-contact rule (martello_impulse_contact_forces
 * on the free accelerations); a contact that the solution opens (lambda = 0, opening
 * acceleration) opens. Leaves
 * a_free in P->a and the multipliers in P->lam. */
static int rigid_multipliers(ida_problem *P, double t, double *u, double *v) {
  int st = martello_eval_acceleration(P->ev, t, u, v, P->a), piv;
  if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t);
  for (int r = 0; r < P->nr; r++) P->lam[r] = 0.0;
  int m = closed_set(P);
  if (m == 0) return MARTELLO_OK;
  if ((st = impulse_columns(P)) != MARTELLO_OK) return fail(P, st, "IDA: singular mass");
  door_list(P, m);
  st = martello_impulse_contact_forces(P->n, m, P->dc, TOPOLOGY(P), P->a, P->rhs,
                                       P->cand, &piv);
  if (st != MARTELLO_OK)
    return fail(P, st, "IDA: the contact forces of %d closed contacts failed at t = %.9e s (%s)", m, t,
                st == MARTELLO_ERR_SINGULAR ? "redundant closed contacts" : "pivot limit");
  for (int k = 0; k < m; k++) {
    int r = P->aset[k];
    if (P->cand[k]) {
      P->lam[r] = P->rhs[k];
    } else {
      P->closed[r] = 0;
      P->opened[r] = 1;
    }
  }
  return MARTELLO_OK;
}

/* Make the state at a restart consistent with the actions in P->act: penalty regimes,
 * impacts, closings, releases; commit; multipliers; y and y' for IDA. u, v hold the state. */
static int prepare_restart(ida_problem *P, double t, double *u, double *v, N_Vector yy,
                           N_Vector yp) {
  int st, any_rigid = 0;
  double ke0 = 0.0, ke1 = 0.0, dummy;
  if ((st = martello_eval_energy(P->ev, u, v, &ke0, &dummy)) != MARTELLO_OK)
    return fail(P, st, "IDA: energy evaluation failed");
  for (int r = 0; r < P->nr; r++) P->opened[r] = 0;
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j];
    double w = pen_rate(P, j, v);
    switch (P->act[j]) {
    case ACT_ONSET:
      nudge(P, j, +1, u);
      martello_observer_set_phase(P->obs, j, 1, t, w);
      P->events++;
      break;
    case ACT_SEPARATION:
      nudge(P, j, -1, u);
      martello_observer_set_phase(P->obs, j, 0, t, w);
      P->events++;
      break;
    case ACT_IMPACT:
      P->w_in[j] = w;
      any_rigid = 1;
      P->events++;
      break;
    case ACT_RELEASE:
      P->closed[r] = 0;
      nudge(P, j, -1, u);
      martello_accumulation_release(&P->acc, P->obs, j, t, w);
      any_rigid = 1;
      P->events++;
      break;
    default:
      break;
    }
  }
  for (int r = 0; r < P->nr; r++) {
    P->was_closed[r] = P->closed[r];
    P->hit[r] = 0;
  }
  if (any_rigid && (st = rigid_impacts(P, t, u, v)) != MARTELLO_OK) return st;
  if (!any_rigid && P->nr > 0 && (st = project_closed(P, t, u, v)) != MARTELLO_OK) return st;
  /* rebounding (not closed) contacts leave from delta < 0 so that the gap root sees the
   * next approach as a sign change */
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r];
    if ((P->hit[r] || P->act[j] == ACT_IMPACT) && !P->closed[r]) nudge(P, j, -1, u);
  }
  if ((st = commit(P, u, v)) != MARTELLO_OK) return fail(P, st, "IDA: commit failed");
  if (P->nr > 0 && (st = rigid_multipliers(P, t, u, v)) != MARTELLO_OK) return st;
  if (P->nr == 0 && (st = martello_eval_acceleration(P->ev, t, u, v, P->a)) != MARTELLO_OK)
    return fail(P, st, "IDA: acceleration failed at t = %.9e s", t);
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r];
    if (P->opened[r]) nudge(P, j, -1, u);
    if ((P->hit[r] || P->act[j] == ACT_IMPACT) && !P->was_closed[r]) {
      /* every impulse is an impact (its rebound as Newton's law left it); a contact it closes
       * is persistent from its accumulation point (an instant later for a plastic impact or
       * one touching at rest), as on the event-driven integrator */
      if (P->hit[r]) martello_observer_add_impact(P->obs, j, t, P->w_in[j], P->w_out[j], 0.0, 0.0);
      if (P->closed[r]) martello_accumulation_hold(&P->acc, P->obs, j);
    } else if (P->opened[r] && martello_observer_in_phase(P->obs, j)) {
      martello_accumulation_release(&P->acc, P->obs, j, t, pen_rate(P, j, v));
    }
  }
  if ((st = martello_eval_energy(P->ev, u, v, &ke1, &dummy)) != MARTELLO_OK)
    return fail(P, st, "IDA: energy evaluation failed");
  P->e_impact += ke0 - ke1;
  /* y and y' */
  double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp);
  apply_B(P, P->lam, P->x);
  if (P->nr > 0 && (st = martello_eval_solve_mass(P->ev, P->x)) != MARTELLO_OK) return fail(P, st, "IDA: singular mass");
  for (int i = 0; i < P->n; i++) {
    y[P->iu[i]] = u[i];
    y[P->iv[i]] = v[i];
    d[P->iu[i]] = v[i];
    d[P->iv[i]] = P->a[i] - (P->nr > 0 ? P->x[i] : 0.0);
  }
  for (int r = 0; r < P->nr; r++) {
    y[P->ip[r]] = P->closed[r] ? P->lam[r] : 0.0;
    y[P->im[r]] = 0.0;
    d[P->ip[r]] = 0.0;
    d[P->im[r]] = 0.0;
  }
  for (int j = 0; j < P->nc; j++) P->act[j] = ACT_NONE;
  if ((st = closed_set_roots(P, u, v)) != MARTELLO_OK)
    return fail(P, MARTELLO_ERR_SINGULAR, "IDA: redundant closed contacts at t = %.9e s (B^T M^-1 B singular)", t);
  return hand_work(P);
}

/* Bisection on the interpolant of the current step for the crossing of delta_j between
 * tl (side sl = sign of delta there) and tr; returns a time on the tl side within event_tol. */
static int locate(ida_problem *P, void *mem, int j, double tl, double tr, N_Vector ytmp,
                  double *t_cross) {
  int flag = IDAGetDky(mem, tl, 0, ytmp);
  if (flag != IDA_SUCCESS)
    return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", tl, IDAGetReturnFlagName(flag));
  gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
  int left_positive = penetration(P, j, P->uq) > 0.0;
  for (int it = 0; it < 200 && tr - tl > fmax(P->event_tol, 4.0 * DBL_EPSILON * fabs(tr)); it++) {
    double tm = 0.5 * (tl + tr);
    flag = IDAGetDky(mem, tm, 0, ytmp);
    if (flag != IDA_SUCCESS)
      return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", tm, IDAGetReturnFlagName(flag));
    gather(P, N_VGetArrayPointer(ytmp), P->uq, P->vq);
    if ((penetration(P, j, P->uq) > 0.0) == left_positive)
      tl = tm;
    else
      tr = tm;
  }
  *t_cross = tl;
  return MARTELLO_OK;
}

/* Decide what the roots reported at tret mean. Returns 1 (and *t_r, P->act) if IDA must
 * restart, 0 if the roots were only extrema of gaps, < 0 on failure. */
static int classify_roots(ida_problem *P, void *mem, double t_last, double tret, const double *y,
                          const int *found, N_Vector ytmp, double *t_r) {
  gather(P, y, P->u, P->v);
  double best = tret;
  int jbest = -1, kbest = ACT_NONE;
  /* extrema of gaps: peaks, and contacts that opened and closed inside one step */
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j];
    if (!found[2 * j + 1] || found[2 * j]) continue;
    if (r >= 0 && P->closed[r]) continue;
    double d = penetration(P, j, P->u);
    int want = ACT_NONE, touching = martello_observer_in_phase(P->obs, j);
    if (r < 0) {
      /* touching with d > 0: the deepest point, sampled there as an accepted state */
      if (!touching && d > 0.0) want = ACT_ONSET;
      else if (touching && d < 0.0) want = ACT_SEPARATION;
    } else if (d > 0.0) {
      want = ACT_IMPACT;
    }
    if (want == ACT_NONE) continue;
    double tc;
    int st = locate(P, mem, j, t_last, tret, ytmp, &tc);
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
    int r = P->rig[j], dir = found[2 * j], touching = martello_observer_in_phase(P->obs, j);
    if (dir == 0) continue;
    if (r < 0) {
      if (dir > 0 && !touching) P->act[j] = ACT_ONSET;
      else if (dir < 0 && touching) P->act[j] = ACT_SEPARATION;
    } else if (!P->closed[r]) {
      if (dir > 0) P->act[j] = ACT_IMPACT;
    } else if (dir < 0) {
      P->act[j] = ACT_RELEASE;
    }
    any |= P->act[j] != ACT_NONE;
  }
  *t_r = tret;
  return any;
}

/* A reported root whose function is exactly 0 at the return stays 0 when two nodes move
 * identically (identical neighbours never touch, docs/problems.md P7; rigid clusters of a chain):
 * IDA would stop on it again at once and fail with "root found at and very near t". A
 * restart with no event lets IDA treat it as inactive until it moves away from 0. */
static int root_stays_zero(ida_problem *P, const double *y, const int *found) {
  gather(P, y, P->uq, P->vq);
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j];
    if (r >= 0 && P->closed[r]) {
      if (found[2 * j] && y[P->ip[r]] == 0.0) return 1;
    } else if ((found[2 * j] && penetration(P, j, P->uq) == 0.0) ||
               (found[2 * j + 1] && pen_rate(P, j, P->vq) == 0.0)) {
      return 1;
    }
  }
  return 0;
}

/* After a step that ended without a root: a contact whose gap lies on the wrong side of its
 * regime (an analytic event time that coincides with a stop time lands exactly on
 * delta = 0, where IDA reports no sign change, and the kink would then sit at the start of
 * every following step). Returns 1 with P->act and *t_r set if IDA must restart. */
static int boundary_events(ida_problem *P, void *mem, double t_last, double tret, const double *y,
                           N_Vector ytmp, double *t_r) {
  gather(P, y, P->u, P->v);
  double best = tret, h_last = 0.0;
  int jbest = -1, kbest = ACT_NONE;
  if (IDAGetLastStep(mem, &h_last) != IDA_SUCCESS) h_last = 0.0;
  double vmax = 0.0;
  for (int i = 0; i < P->n; i++) vmax = fmax(vmax, fabs(P->v[i]));
  double wtol = 10.0 * (P->rtol * vmax + P->atol);
  for (int j = 0; j < P->nc; j++) {
    int r = P->rig[j], want = ACT_NONE, touching = martello_observer_in_phase(P->obs, j);
    if (r >= 0 && P->closed[r]) continue;
    double d = penetration(P, j, P->u), w = pen_rate(P, j, P->v);
    /* on the surface within round-off of the gap, or of the time */
    double on = 64.0 * DBL_EPSILON *
                (fabs(node_u(P->con_a[j], P->u)) + fabs(node_u(P->con_b[j], P->u)) + fabs(P->gap[j]) +
                 fabs(w) * (fabs(tret) + fabs(h_last)));
    /* ... and moving across it faster than the integration error of a rate: two bodies
     * that travel together at zero gap are not a new event */
    if (r < 0) {
      if (!touching && (d > 0.0 || (d >= -on && w > wtol))) want = ACT_ONSET;
      else if (touching && (d < 0.0 || (d <= on && w < -wtol))) want = ACT_SEPARATION;
    } else if (d > 0.0 || (d >= -on && w > wtol)) {
      want = ACT_IMPACT;
    }
    if (want == ACT_NONE) continue;
    double tc = tret;
    int wrong_side = r < 0 ? (touching ? d < 0.0 : d > 0.0) : d > 0.0;
    if (wrong_side && fabs(d) > on && tret > t_last) {
      int st = locate(P, mem, j, t_last, tret, ytmp, &tc);
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

/* ---- set-up ----------------------------------------------------------------------------- */

/* calloc(count) (at least one element); on failure its size is kept in *failed (the
 * first that failed), for the out-of-memory line */
static void *take(size_t count, size_t size, double *failed) {
  void *p = calloc(count > 0 ? count : 1, size);
  if (!p && *failed == 0.0) *failed = (double)(count > 0 ? count : 1) * (double)size;
  return p;
}

/* An allocation failed: the library's out-of-memory line for what (for the run's n nodes
 * and nc contacts) and bytes (< 0: allocated inside SUNDIALS, amount not known). */
static int fail_memory(ida_problem *P, const char *what, double bytes) {
  char of[192], line[480];
  snprintf(of, sizeof of, "%s for a scene of %d nodes and %d contacts", what, P->n, P->nc);
  martello_memory_message(of, bytes, NULL, line, (int)sizeof line);
  return martello_observer_fail(P->obs, MARTELLO_ERR_MEMORY, P->t_now, line);
}

static void release(ida_problem *P) {
  void *all[] = {P->mass, P->gap, P->rest, P->fixed, P->con_a, P->con_b, P->scheme, P->rig,
                 P->rig_con, P->iu, P->iv, P->ip, P->im, P->closed, P->act,
                 P->opened, P->was_closed, P->hit, P->cand, P->q, P->w0, P->w_in, P->u, P->v, P->a, P->x, P->uq, P->vq, P->fint, P->fext,
                 P->force, P->lam, P->S, P->rhs, P->mb, P->cols, P->dc, P->aset,
                 P->sw_a, P->sw_b, P->sw_al, P->sw_be, P->sw_ga, P->w_out, P->lc, P->dlc, P->Wc, P->ar, P->lr, P->lamtol,
                 P->v_last, P->el0, P->el1, P->elc, P->pv0, P->pa0, P->pj0, P->pv1, P->pa1,
                 P->pj1, P->ua, P->va, P->aa};
  for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) free(all[k]);
  if (P->ev) martello_eval_free(&P->ev);
  martello_accumulation_free(&P->acc);
}

/* Half-bandwidth of the Jacobian in the interleaved layout: the node couplings are probed
 * (which accelerations change when one node's u or v does, at the initial state) and
 * completed with the contacts of the topology (penalty contacts are open at t = 0). */
static int bandwidth(ida_problem *P, const double *u0, const double *v0, sunindextype *bw) {
  int n = P->n, st, dnode = 0;
  double *base = P->a, *pert = P->fint, *up = P->uq, *vp = P->vq;
  if ((st = martello_eval_acceleration(P->ev, 0.0, u0, v0, base)) != MARTELLO_OK) return st;
  memcpy(up, u0, sizeof(double) * (size_t)n);
  memcpy(vp, v0, sizeof(double) * (size_t)n);
  for (int k = 0; k < n; k++) {
    if (P->fixed[k]) continue;
    /* u_k and v_k together: a stiffness or a damping coupling shows either way */
    up[k] += 1e-6 * (fabs(up[k]) + 1.0);
    vp[k] += 1e-6 * (fabs(vp[k]) + 1.0);
    if ((st = martello_eval_acceleration(P->ev, 0.0, up, vp, pert)) != MARTELLO_OK) return st;
    for (int i = 0; i < n; i++)
      if (pert[i] != base[i]) dnode = abs(i - k) > dnode ? abs(i - k) : dnode;
    up[k] = u0[k];
    vp[k] = v0[k];
  }
  for (int j = 0; j < P->nc; j++)
    if (P->con_a[j] >= 0 && P->con_b[j] >= 0 && P->rig[j] < 0)
      dnode = abs(P->con_a[j] - P->con_b[j]) > dnode ? abs(P->con_a[j] - P->con_b[j]) : dnode;
  sunindextype b = 1;
#define WIDEN(p, q) do { sunindextype d_ = (p) > (q) ? (p) - (q) : (q) - (p); if (d_ > b) b = d_; } while (0)
  for (int i = 0; i < n; i++)
    for (int k = i - dnode; k <= i + dnode; k++) {
      if (k < 0 || k >= n) continue;
      WIDEN(P->iv[i], P->iu[k]);
      WIDEN(P->iv[i], P->iv[k]);
    }
  for (int r = 0; r < P->nr; r++) {
    int j = P->rig_con[r], ends[2] = {P->con_a[j], P->con_b[j]};
    for (int e = 0; e < 2; e++) {
      if (ends[e] < 0) continue;
      WIDEN(P->ip[r], P->iv[ends[e]]);
      WIDEN(P->im[r], P->iu[ends[e]]);
    }
  }
#undef WIDEN
  *bw = b;
  return MARTELLO_OK;
}

static int setup(ida_problem *P, martello_model *model, martello_run *run) {
  int st, n, nc, ncp;
  double failed = 0.0;
  martello_settings s;
  P->model = model;
  P->run = run;
  if ((st = martello_run_settings(run, &s)) != MARTELLO_OK) return st;
  P->rtol = s.rtol;
  P->atol = s.atol;
  P->event_tol = s.event_tol;
  P->t_end = s.t_end;
  P->h_max = s.h_max;
  P->every = s.every;
  P->out_dt = s.dt * s.every;
  P->dt = s.dt;
  if ((st = martello_model_topology(model, &n, &nc, NULL, NULL, NULL, NULL, NULL, NULL, NULL,
                                    &ncp)) != MARTELLO_OK)
    return fail(P, st, "IDA: could not read the model");
  P->n = n;
  P->nc = nc;
  P->ncoupling = ncp;
  P->mass = take((size_t)n, sizeof(double), &failed);
  P->fixed = take((size_t)n, sizeof(int), &failed);
  P->con_a = take((size_t)nc, sizeof(int), &failed);
  P->con_b = take((size_t)nc, sizeof(int), &failed);
  P->scheme = take((size_t)nc, sizeof(int), &failed);
  P->gap = take((size_t)nc, sizeof(double), &failed);
  P->rest = take((size_t)nc, sizeof(double), &failed);
  if (failed > 0.0) return fail_memory(P, "an array of the IDA state", failed);
  if ((st = martello_model_topology(model, &n, &nc, P->mass, P->fixed, P->con_a, P->con_b,
                                    P->scheme, P->gap, P->rest, &ncp)) != MARTELLO_OK)
    return fail(P, st, "IDA: could not read the model");
  P->rig = take((size_t)nc, sizeof(int), &failed);
  P->rig_con = take((size_t)nc, sizeof(int), &failed);
  if (failed > 0.0) return fail_memory(P, "an array of the IDA state", failed);
  P->nr = 0;
  for (int j = 0; j < nc; j++) {
    if (P->scheme[j] == MARTELLO_SCHEME_LAGRANGE || P->scheme[j] == MARTELLO_SCHEME_RESTITUTION) {
      P->rig[j] = P->nr;
      P->rig_con[P->nr++] = j;
    } else if (P->scheme[j] == MARTELLO_SCHEME_PENALTY) {
      P->rig[j] = -1;
    } else {
      return fail(P, MARTELLO_ERR_UNSUPPORTED, "contact %d: this scheme cannot run on IDA", j);
    }
  }
  size_t nr = (size_t)P->nr, un = (size_t)n, ucn = (size_t)nc;
  P->iu = take(un, sizeof(sunindextype), &failed);
  P->iv = take(un, sizeof(sunindextype), &failed);
  P->ip = take(nr, sizeof(sunindextype), &failed);
  P->im = take(nr, sizeof(sunindextype), &failed);
  P->closed = take(nr, sizeof(int), &failed);
  P->opened = take(nr, sizeof(int), &failed);
  P->was_closed = take(nr, sizeof(int), &failed);
  P->hit = take(nr, sizeof(int), &failed);
  P->cand = take(nr, sizeof(int), &failed);
  P->q = take(nr, sizeof(double), &failed);
  P->w0 = take(nr, sizeof(double), &failed);
  P->dc = take(nr, sizeof(int), &failed);
  P->cols = take(nr * un, sizeof(double), &failed);
  P->aset = take(nr, sizeof(int), &failed);
  P->lam = take(nr, sizeof(double), &failed);
  P->rhs = take(nr, sizeof(double), &failed);
  P->S = take(nr * nr, sizeof(double), &failed);
  P->act = take(ucn, sizeof(int), &failed);
  P->w_in = take(ucn, sizeof(double), &failed);
  P->force = take(ucn, sizeof(double), &failed);
  P->w_out = take(ucn, sizeof(double), &failed);
  P->lc = take(nr, sizeof(int), &failed);
  P->dlc = take(nr, sizeof(int), &failed);
  P->Wc = take(nr * nr, sizeof(double), &failed);
  P->ar = take(un, sizeof(double), &failed);
  P->lr = take(nr, sizeof(double), &failed);
  P->lamtol = take(nr, sizeof(double), &failed);
  P->v_last = take(un, sizeof(double), &failed);
  double **work[] = {&P->u, &P->v, &P->a, &P->x, &P->uq, &P->vq, &P->fint, &P->fext, &P->mb};
  for (size_t k = 0; k < sizeof work / sizeof work[0]; k++) *work[k] = take(un, sizeof(double), &failed);
  if (failed > 0.0) return fail_memory(P, "an array of the IDA state", failed);
  /* layout: node i's (u, v), then the (P, mu) of the rigid contacts whose first node is i
   * (between the two nodes of a chain link: half-bandwidth 3, 5 with links) */
  sunindextype pos = 0;
  for (int i = 0; i < n; i++) {
    P->iu[i] = pos++;
    P->iv[i] = pos++;
    for (int r = 0; r < P->nr; r++) {
      int j = P->rig_con[r], a = P->con_a[j], b = P->con_b[j];
      int first = (a >= 0 && b >= 0) ? (a < b ? a : b) : (a > b ? a : b);
      if (first == i) {
        P->ip[r] = pos++;
        P->im[r] = pos++;
      }
    }
  }
  P->N = pos;
  if (martello_accumulation_init(&P->acc, nc, P->t_end) != MARTELLO_OK)
    return fail_memory(P, "the accumulation phases of the IDA run", (double)nc * sizeof(double));
  if ((st = martello_eval_create(model, &P->ev)) == MARTELLO_ERR_MEMORY) {
    char line[480]; /* the model's message is the line (martello_eval_create) */
    martello_model_message(model, line, (int)sizeof line);
    return martello_observer_fail(P->obs, st, P->t_now, line);
  }
  if (st != MARTELLO_OK) return fail(P, st, "IDA: could not create the force evaluator");
  if ((st = martello_eval_link_count(P->ev, &P->nl)) != MARTELLO_OK)
    return fail(P, st, "IDA: martello_eval_link_count failed");
  {
    const size_t ne = 4 * ((size_t)nc + (size_t)P->nl);
    double **el[] = {&P->el0, &P->el1, &P->elc};
    double **nd[] = {&P->pv0, &P->pa0, &P->pj0, &P->pv1, &P->pa1, &P->pj1, &P->ua, &P->va, &P->aa};
    for (size_t k = 0; k < sizeof el / sizeof el[0]; k++) *el[k] = take(ne, sizeof(double), &failed);
    for (size_t k = 0; k < sizeof nd / sizeof nd[0]; k++) *nd[k] = take((size_t)n, sizeof(double), &failed);
    if (failed > 0.0) return fail_memory(P, "an array of the IDA state", failed);
  }
  /* every switching surface of the laws is a root: hold them on smooth branches */
  if ((st = martello_eval_use_branches(P->ev, &P->nsw)) != MARTELLO_OK)
    return fail(P, st, "IDA: martello_eval_use_branches failed");
  P->sw_a = take((size_t)P->nsw, sizeof(int), &failed);
  P->sw_b = take((size_t)P->nsw, sizeof(int), &failed);
  P->sw_al = take((size_t)P->nsw, sizeof(double), &failed);
  P->sw_be = take((size_t)P->nsw, sizeof(double), &failed);
  P->sw_ga = take((size_t)P->nsw, sizeof(double), &failed);
  if (failed > 0.0) return fail_memory(P, "an array of the IDA state", failed);
  if (P->nsw > 0 &&
      (st = martello_eval_switches(P->ev, P->sw_a, P->sw_b, P->sw_al, P->sw_be, P->sw_ga)) != MARTELLO_OK)
    return fail(P, st, "IDA: martello_eval_switches failed");
  return MARTELLO_OK;
}

/* ---- the run ------------------------------------------------------------------------------ */

/* IDA's first step (docs/ida.md, initial step): IDA guesses it from the first stop time,
 * which from rest with a far output makes its first-order error test fail down to h_min; so
 * at the start and at every restart: the first step h of order 1 errs by h^2 |y''|/2 per
 * component; y'' = (a, a') at the restart (a' by a
 * forward difference along the motion) and h0 = SAFETY min_i sqrt(2 w_i / |y''_i|), w_i =
 * rtol |y_i| + atol, capped at 1e-3 of the output interval, as on the GSL path. */
#define SAFETY 0.1   /* IDA's first-order error estimate is crude: a margin below it */
static int initial_step(ida_problem *P, double t, const double *u, const double *v, double *h0) {
  const int n = P->n;
  const double cap = 1e-3 * fmin(P->out_dt, P->t_end), d = 1e-6 * cap;
  int st = martello_eval_acceleration(P->ev, t, u, v, P->a);
  if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t);
  for (int i = 0; i < n; i++) {
    P->uq[i] = u[i] + d * v[i];
    P->vq[i] = v[i] + d * P->a[i];
  }
  st = martello_eval_acceleration(P->ev, t + d, P->uq, P->vq, P->x);
  if (st != MARTELLO_OK) return fail(P, st, "IDA: acceleration failed at t = %.9e s", t + d);
  *h0 = cap;
  for (int i = 0; i < n; i++) {
    double ju = fabs(P->a[i]), jv = fabs(P->x[i] - P->a[i]) / d;
    double wu = P->rtol * fabs(u[i]) + P->atol, wv = P->rtol * fabs(v[i]) + P->atol;
    if (ju > 0.0) *h0 = fmin(*h0, SAFETY * sqrt(2.0 * wu / ju));
    if (jv > 0.0) *h0 = fmin(*h0, SAFETY * sqrt(2.0 * wv / jv));
  }
  return MARTELLO_OK;
}

/* The extrema of the node displacements on [t0, t1], inside IDA's last step: a node whose
 * velocity changes sign against P->v_last gets the root of v located by bisection on IDA's
 * interpolant (IDAGetDky, of the method's order: the error of the step) and u there
 * (docs/run-layer.md, located extrema). */
static int node_extrema(ida_problem *P, void *mem, double t0, double t1, const double *y1,
                        N_Vector ytmp) {
  for (int i = 0; i < P->n; i++) {
    const double v0 = P->v_last[i], v1 = y1[P->iv[i]];
    int is_max;
    if (P->fixed[i]) continue;
    if (v0 > 0.0 && v1 <= 0.0) is_max = 1;
    else if (v0 < 0.0 && v1 >= 0.0) is_max = 0;
    else continue;
    double lo = t0, hi = t1, u = y1[P->iu[i]];
    for (int it = 0; it < 200 && hi - lo > fmax(P->event_tol, 4.0 * DBL_EPSILON * fabs(hi)); it++) {
      const double tm = 0.5 * (lo + hi);
      int flag = IDAGetDky(mem, tm, 0, ytmp);
      if (flag != IDA_SUCCESS)
        return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", tm,
                    IDAGetReturnFlagName(flag));
      if ((N_VGetArrayPointer(ytmp)[P->iv[i]] > 0.0) == (v0 > 0.0)) lo = tm; else hi = tm;
    }
    if (hi < t1) {
      int flag = IDAGetDky(mem, hi, 0, ytmp);
      if (flag != IDA_SUCCESS)
        return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", hi,
                    IDAGetReturnFlagName(flag));
      u = N_VGetArrayPointer(ytmp)[P->iu[i]];
    }
    int st = martello_observer_extremum(P->obs, i, hi, u, is_max);
    if (st != MARTELLO_OK) return fail(P, st, "IDA: martello_observer_extremum failed");
  }
  return MARTELLO_OK;
}

/* u, v, a (P->ua, va, aa) of the nodes at t on the last step's interpolant (IDAGetDky: y
 * and y'; a is the v rows of y'). */
static int interpolated(ida_problem *P, double t) {
  void *mem = P->mem_now;
  int f0 = IDAGetDky(mem, t, 0, P->ytd);
  if (f0 != IDA_SUCCESS)
    return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", t, IDAGetReturnFlagName(f0));
  gather(P, N_VGetArrayPointer(P->ytd), P->ua, P->va);
  f0 = IDAGetDky(mem, t, 1, P->ytd);
  if (f0 != IDA_SUCCESS)
    return fail(P, MARTELLO_ERR_EXTERNAL, "IDAGetDky failed at t = %.9e s: %s", t, IDAGetReturnFlagName(f0));
  for (int i = 0; i < P->n; i++) P->aa[i] = N_VGetArrayPointer(P->ytd)[P->iv[i]];
  return MARTELLO_OK;
}

/* The rates of the peak quantities at t on the interpolant: elements into e (packed), node
 * jerks into jerk; P->va, P->aa hold v and a there. */
static int interpolated_rates(ida_problem *P, double t, double *e, double *jerk) {
  int st = interpolated(P, t);
  if (st != MARTELLO_OK) return st;
  st = martello_peak_rates(P->ev, t, P->ua, P->va, P->aa, P->nc, P->nl, e, jerk);
  return st == MARTELLO_OK ? st : fail(P, st, "IDA: the rates of the peaks failed at t = %.9e s", t);
}

/* The probe of c/located_peaks.c on IDA's interpolant of the last step (of the method's
 * order: its own solution between the steps' ends). */
static int peak_probe(void *ctx, double t, int kind, int j, double *q, double *r) {
  ida_problem *P = ctx;
  int st = interpolated_rates(P, t, P->elc, P->x);
  if (st != MARTELLO_OK) return st;
  martello_peak_pick(kind, j, P->nc, P->nl, P->va, P->aa, P->x, P->elc, q, r);
  return MARTELLO_OK;
}

/* Fixed nodes, rigid contacts and penalty contacts out of a phase have no peak here. */
static int peak_skip(void *ctx, int kind, int j) {
  ida_problem *P = ctx;
  if (kind == MARTELLO_PEAK_V || kind == MARTELLO_PEAK_A) return P->fixed[j];
  if (kind == MARTELLO_PEAK_PEN || kind == MARTELLO_PEAK_FORCE)
    return P->rig[j] >= 0 || !martello_observer_in_phase(P->obs, j);
  return 0;
}

/* The peaks inside [t0, t1] of IDA's last step, on its interpolant (docs/run-layer.md,
 * located peaks): every quantity's value and rate at both ends (the start's kept from the
 * last step's end when IDA went on: P->start_rates), then c/located_peaks.c. */
static int located_peaks(ida_problem *P, void *mem, double t0, double t1, int at_event) {
  const int n = P->n;
  martello_peak_ends e;
  int st;
  if (!(t1 > t0)) return MARTELLO_OK;
  P->mem_now = mem;
  if (!P->start_rates) {
    if ((st = interpolated_rates(P, t0, P->el0, P->pj0)) != MARTELLO_OK) return st;
    memcpy(P->pv0, P->va, sizeof(double) * (size_t)n);
    memcpy(P->pa0, P->aa, sizeof(double) * (size_t)n);
  }
  if ((st = interpolated_rates(P, t1, P->el1, P->pj1)) != MARTELLO_OK) return st;
  memcpy(P->pv1, P->va, sizeof(double) * (size_t)n);
  memcpy(P->pa1, P->aa, sizeof(double) * (size_t)n);
  memset(&e, 0, sizeof e);
  martello_peak_ends_set(&e, 0, n, P->nc, P->nl, P->pv0, P->pa0, P->pj0, P->el0);
  martello_peak_ends_set(&e, 1, n, P->nc, P->nl, P->pv1, P->pa1, P->pj1, P->el1);
  e.skip = peak_skip;
  if (at_event && (st = martello_peak_fold_end(P->obs, &e, P)) != MARTELLO_OK) return st;
  return martello_locate_peaks(P->obs, &e, t0, t1, P->rtol, P->event_tol, peak_probe, P);
}

/* After a step: its end's rates are the next step's start unless IDA restarts there (the
 * state and the laws' branches change at a restart). */
static void keep_end_rates(ida_problem *P, int unchanged) {
  double *tmp;
  P->start_rates = unchanged;
  if (!unchanged) return;
  tmp = P->el0; P->el0 = P->el1; P->el1 = tmp;
  tmp = P->pj0; P->pj0 = P->pj1; P->pj1 = tmp;
  tmp = P->pv0; P->pv0 = P->pv1; P->pv1 = tmp;
  tmp = P->pa0; P->pa0 = P->pa1; P->pa1 = tmp;
}

/* The next stop after t: the output time t_out, or a kink of the load before it. */
static double next_stop(ida_problem *P, double t, double t_out) {
  double tb = DBL_MAX;
  if (martello_eval_next_breakpoint(P->ev, t, &tb) != MARTELLO_OK) tb = DBL_MAX;
  return fmin(tb, t_out);
}

static int check(ida_problem *P, int flag, const char *call) {
  if (flag >= 0) return MARTELLO_OK;
  return fail(P, MARTELLO_ERR_EXTERNAL, "%s failed: %s", call, IDAGetReturnFlagName(flag));
}

static int integrate(ida_problem *P, SUNContext sunctx, void **memp, N_Vector yy, N_Vector yp,
                     N_Vector id, N_Vector ytmp, SUNMatrix *Jp, SUNLinearSolver *LSp) {
  int st, n = P->n;
  double *u0 = P->u, *v0 = P->v;
  if ((st = martello_model_initial_state(P->model, u0, v0)) != MARTELLO_OK)
    return fail(P, st, "IDA: could not read the initial state");
  for (int i = 0; i < n; i++)
    if (P->fixed[i]) v0[i] = 0.0;

  /* linear solver: band in the interleaved layout when it pays (chains), dense otherwise or
   * with consistent-mass couplings (M^-1 is full) */
  sunindextype bw = P->N;
  if (P->ncoupling == 0 && P->N > 8 && (st = bandwidth(P, u0, v0, &bw)) != MARTELLO_OK)
    return fail(P, st, "IDA: force evaluation failed while probing the bandwidth");
  int banded = 2 * bw + 1 < P->N / 2;

  /* initial contact states: penalty contacts already penetrated are in a phase from t = 0
   * (the observer opens it); rigid contacts at zero gap that approach or rest are resolved as
   * impacts at t = 0 */
  double vtol = speed_tol(P, v0);
  for (int j = 0; j < P->nc; j++) {
    double d = penetration(P, j, u0), w = pen_rate(P, j, v0);
    if (P->rig[j] < 0) {
      if (d == 0.0 && w > 0.0) P->act[j] = ACT_ONSET;
    } else {
      double htol = position_tol(P, j, u0);
      if (d > htol)
        return fail(P, MARTELLO_ERR_ARGUMENT, "contact %d starts penetrated by %.3e m (rigid contacts need delta <= 0 at t = 0)", j, d);
      if (d >= -htol && w >= -vtol) P->act[j] = ACT_IMPACT;
    }
  }
  if ((st = martello_observer_begin(P->obs, P->ev, u0, v0, "tighten rtol and atol")) != MARTELLO_OK)
    /* out of memory: the observer failed the run with its line */
    return st == MARTELLO_ERR_MEMORY ? st : fail(P, st, "IDA: martello_observer_begin failed");
  if ((st = prepare_restart(P, 0.0, u0, v0, yy, yp)) != MARTELLO_OK) return st;

  /* IDA: create, init, options (SUNDIALS lifecycle) */
  void *mem = IDACreate(sunctx);
  if (!mem) return fail_memory(P, "the IDA solver memory (IDACreate)", -1.0);
  *memp = mem;
  if ((st = check(P, IDASetErrHandlerFn(mem, error_handler, P), "IDASetErrHandlerFn"))) return st;
  if ((st = check(P, IDAInit(mem, residual, 0.0, yy, yp), "IDAInit"))) return st;
  /* vector tolerances: atol for u, v and P; the GGL multiplier mu is out of the Newton test.
   * mu vanishes on the exact solution and only absorbs the round-off of delta = 0, amplified
   * by c_j ~ 1/h in the index-2 Newton matrix (a node-to-node gap is zero only to ~eps|u|,
   * which gives mu ~ c_j m eps |u|): judged with atol it would fail every short step. Its
   * effect on u is tested through u itself. */
  double *av = N_VGetArrayPointer(id);
  for (sunindextype k = 0; k < P->N; k++) av[k] = P->atol;
  for (int r = 0; r < P->nr; r++) av[P->im[r]] = 1e30;
  if ((st = check(P, IDASVtolerances(mem, P->rtol, id), "IDASVtolerances"))) return st;
  if ((st = check(P, IDASetUserData(mem, P), "IDASetUserData"))) return st;
  *Jp = banded ? SUNBandMatrix(P->N, bw, bw, sunctx) : SUNDenseMatrix(P->N, P->N, sunctx);
  if (!*Jp) return fail_memory(P, "the IDA Jacobian matrix", -1.0);
  *LSp = banded ? SUNLinSol_Band(yy, *Jp, sunctx) : SUNLinSol_Dense(yy, *Jp, sunctx);
  if (!*LSp) return fail_memory(P, "the IDA linear solver", -1.0);
  if ((st = check(P, IDASetLinearSolver(mem, *LSp, *Jp), "IDASetLinearSolver"))) return st;
  if (P->h_max > 0.0 && (st = check(P, IDASetMaxStep(mem, P->h_max), "IDASetMaxStep"))) return st;
  double h0;
  if ((st = initial_step(P, 0.0, u0, v0, &h0)) != MARTELLO_OK) return st;
  if ((st = check(P, IDASetInitStep(mem, h0), "IDASetInitStep"))) return st;
  double *idv = N_VGetArrayPointer(id);
  for (sunindextype k = 0; k < P->N; k++) idv[k] = 1.0;
  for (int r = 0; r < P->nr; r++) idv[P->ip[r]] = idv[P->im[r]] = 0.0;
  if ((st = check(P, IDASetId(mem, id), "IDASetId"))) return st;
  if (P->nr > 0 && (st = check(P, IDASetSuppressAlg(mem, SUNTRUE), "IDASetSuppressAlg"))) return st;
  if (P->nc + P->nsw > 0) {
    if ((st = check(P, IDARootInit(mem, 2 * P->nc + P->nsw, roots), "IDARootInit"))) return st;
    if ((st = check(P, IDASetNoInactiveRootWarn(mem), "IDASetNoInactiveRootWarn"))) return st;
  }

  int k_out = 1;
  double t_out = fmin((double)P->every * P->dt, P->t_end), t_last = 0.0;
  if ((st = observe(P, 0.0, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), 0)) != MARTELLO_OK) return st;
  for (int i = 0; i < n; i++) P->v_last[i] = N_VGetArrayPointer(yy)[P->iv[i]];
  double t_stop = next_stop(P, 0.0, t_out);
  if ((st = check(P, IDASetStopTime(mem, t_stop), "IDASetStopTime"))) return st;
  const size_t n_found = (size_t)(2 * P->nc + P->nsw + 1);
  int *found = calloc(n_found, sizeof(int));
  if (!found) return fail_memory(P, "the IDA root flags", (double)(n_found * sizeof(int)));
  long steps = 0;
  int same_time = 0;
  double t_prev_restart = -1.0;
  st = MARTELLO_OK;
  while (t_last < P->t_end) {
    double tret = t_last;
    int flag = IDASolve(mem, t_out, &tret, yy, yp, IDA_ONE_STEP);
    if (flag < 0) {
      double tcur = t_last;
      if (IDAGetCurrentTime(mem, &tcur) != IDA_SUCCESS) tcur = t_last;
      P->t_now = tcur;
      /* a state, rate or step that overflowed (an error norm of inf gives a step of 0 or
       * NaN) makes IDA blame its inputs, e.g. a stop time "behind" the current time: that
       * is a divergence, not an IDA failure */
      double hcur = 0.0;
      if (IDAGetCurrentStep(mem, &hcur) == IDA_SUCCESS && !(isfinite(hcur) && hcur != 0.0))
        P->nan_seen = 1;
      if (!isfinite(tcur)) P->nan_seen = 1;
      for (sunindextype k = 0; k < P->N; k++)
        if (!isfinite(N_VGetArrayPointer(yy)[k])) P->nan_seen = 1;
      if (P->nan_seen)
        st = martello_observer_fail(P->obs, MARTELLO_ERR_DIVERGED, tcur, NULL);
      else
        st = fail(P, MARTELLO_ERR_EXTERNAL, "IDASolve failed at t = %.9e s: %s (%s)", tcur, IDAGetReturnFlagName(flag), P->ida_msg);
      break;
    }
    P->nan_seen = 0;
    if (++steps > MAX_STEPS) {
      st = fail(P, MARTELLO_ERR_NOT_CONVERGED, "IDA: more than %ld steps before t = %.9e s", MAX_STEPS, tret);
      break;
    }
    int restart = 0;
    double t_r = tret;
    if (flag == IDA_ROOT_RETURN) {
      if ((st = check(P, IDAGetRootInfo(mem, found), "IDAGetRootInfo"))) break;
      restart = classify_roots(P, mem, t_last, tret, N_VGetArrayPointer(yy), found, ytmp, &t_r);
      if (restart < 0) {
        st = restart;
        break;
      }
      if (!restart) restart = root_stays_zero(P, N_VGetArrayPointer(yy), found);
      /* a branch of a law left: the commit at the root changes it, IDA restarts there */
      for (int s = 0; s < P->nsw && !restart; s++)
        if (found[2 * P->nc + s]) restart = 1;
    }
    /* a kink of the load (docs/ida.md, time events): IDA restarts across it */
    if (!restart && flag == IDA_TSTOP_RETURN && tret == t_stop && t_stop < t_out) restart = 1;
    if (!restart) {
      restart = boundary_events(P, mem, t_last, tret, N_VGetArrayPointer(yy), ytmp, &t_r);
      if (restart < 0) {
        st = restart;
        break;
      }
    }
    if (restart && t_r < tret) {
      int f0 = IDAGetDky(mem, t_r, 0, yy), f1 = IDAGetDky(mem, t_r, 1, yp);
      if ((st = check(P, f0 < 0 ? f0 : f1, "IDAGetDky"))) break;
    }
    if ((st = work_quadrature(P, mem, t_last, t_r, ytmp)) != MARTELLO_OK) break;
    if ((st = node_extrema(P, mem, t_last, t_r, N_VGetArrayPointer(yy), ytmp)) != MARTELLO_OK) break;
    if ((st = located_peaks(P, mem, t_last, t_r, restart)) != MARTELLO_OK) break;
    keep_end_rates(P, !restart);
    t_last = t_r;
    P->t_now = t_r;
    const double *y = N_VGetArrayPointer(yy);
    gather(P, y, P->u, P->v);
    if (restart) {
      same_time = t_r - t_prev_restart <= 1e-12 * fmax(fabs(t_r), P->out_dt) ? same_time + 1 : 0;
      t_prev_restart = t_r;
      if (same_time > 8 * (P->nc + 2)) {
        st = fail(P, MARTELLO_ERR_NOT_CONVERGED, "IDA: contact events keep recurring at t = %.9e s without progress", t_r);
        break;
      }
      if ((st = flush_counts(P, mem)) != MARTELLO_OK) break;
      if ((st = prepare_restart(P, t_r, P->u, P->v, yy, yp)) != MARTELLO_OK) break;
    } else {
      if ((st = commit(P, P->u, P->v)) != MARTELLO_OK) {
        st = fail(P, st, "IDA: commit failed");
        break;
      }
      if ((st = hand_work(P)) != MARTELLO_OK) break;
    }
    /* an output time reached (tstop), or passed within round-off by a restart: grid point
     * k_out·every of the output interval dt (the observer records it) */
    int at_output = t_r == t_out || (restart && t_out - t_r <= 16.0 * DBL_EPSILON * t_out);
    if ((st = observe(P, t_r, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp),
                      at_output ? k_out * P->every : -1)) != MARTELLO_OK)
      break;
    for (int i = 0; i < n; i++) P->v_last[i] = N_VGetArrayPointer(yy)[P->iv[i]];   /* after a restart's jumps */
    if (at_output) {
      if (t_out >= P->t_end) {
        t_last = P->t_end;
        break;
      }
      k_out++;
      t_out = fmin((double)(k_out * P->every) * P->dt, P->t_end);   /* t = k dt, as on GSL */
      if (P->t_end - t_out <= 1e-9 * P->out_dt) t_out = P->t_end;
    }
    if (restart) {
      double h0;
      gather(P, N_VGetArrayPointer(yy), P->u, P->v);
      if ((st = initial_step(P, t_r, P->u, P->v, &h0)) != MARTELLO_OK) break;
      if ((st = check(P, IDASetInitStep(mem, h0), "IDASetInitStep"))) break;
      if ((st = check(P, IDAReInit(mem, t_r, yy, yp), "IDAReInit"))) break;
      reset_count_baseline(P);
    }
    if (restart || at_output || tret >= t_stop) {
      t_stop = next_stop(P, t_r, t_out);
      if ((st = check(P, IDASetStopTime(mem, t_stop), "IDASetStopTime"))) break;
    }
  }
  free(found);
  int st2 = flush_counts(P, mem);
  if (st == MARTELLO_OK) st = st2;
  if (st == MARTELLO_OK) st = martello_observer_finish(P->obs, t_last);
  return st;
}

int martello_ida_run(martello_model *model, martello_run *run) {
  ida_problem prob;
  ida_problem *P = &prob;
  memset(P, 0, sizeof *P);
  P->run = run;
  if (!model || !run) return MARTELLO_ERR_ARGUMENT;
  int st = martello_run_observer(run, &P->obs);
  if (st != MARTELLO_OK) return st;
  st = setup(P, model, run);
  SUNContext sunctx = NULL;
  void *mem = NULL;
  N_Vector yy = NULL, yp = NULL, id = NULL, ytmp = NULL;
  SUNMatrix J = NULL;
  SUNLinearSolver LS = NULL;
  if (st == MARTELLO_OK && SUNContext_Create(NULL, &sunctx) != 0)
    st = fail(P, MARTELLO_ERR_EXTERNAL, "SUNContext_Create failed");
  if (st == MARTELLO_OK) {
    yy = N_VNew_Serial(P->N, sunctx);
    yp = N_VNew_Serial(P->N, sunctx);
    id = N_VNew_Serial(P->N, sunctx);
    ytmp = N_VNew_Serial(P->N, sunctx);
    P->ytd = N_VNew_Serial(P->N, sunctx);
    if (!yy || !yp || !id || !ytmp || !P->ytd)
      st = fail_memory(P, "the IDA state vectors", -1.0);
  }
  /* a failed run keeps what it computed (the observer closed its open phases) */
  if (st == MARTELLO_OK) st = integrate(P, sunctx, &mem, yy, yp, id, ytmp, &J, &LS);
  if (mem) IDAFree(&mem);
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  if (yy) N_VDestroy(yy);
  if (yp) N_VDestroy(yp);
  if (id) N_VDestroy(id);
  if (ytmp) N_VDestroy(ytmp);
  if (P->ytd) N_VDestroy(P->ytd);
  if (sunctx) SUNContext_Free(&sunctx);
  release(P);
  return st;
}
