/* Event-driven integration of a scene on GSL odeiv2 (rkf45, rk8pd, msbdf); the method, the
 * sign conventions and the choices made are in docs/event-driven.md.
 *
 *  - The state y = [u; v; W_ext; W_int; W_links; W_contact] (n nodes; the work integrals
 *    of the external forces, of all internal forces, of the links other than dampers and of
 *    the penalty contacts ride along outside the error control) is advanced by
 *    gsl_odeiv2_evolve_apply one accepted step at a time,
 *    stepping exactly onto the output times. Every accepted step commits the path-dependent
 *    link states (martello_eval_commit) and is a sample of the run's observer, which
 *    measures it as it measures every integrator (martello_observer_*, docs/run-layer.md).
 *  - Events are roots located to event_tol in time by Illinois iterations on states
 *    re-integrated from the start of the step (the stepper's own one-step method with a
 *    shorter step; for msbdf, whose multistep history cannot restart there, an adaptive
 *    A-stable rk4imp): the gap of a restitution/Lagrange contact closing (impact), the gap of
 *    a penalty contact crossing 0 either way (no step straddles the kink of the law), and the
 *    multiplier of a persistent contact turning tensile (release). A quintic Hermite
 *    interpolant of the gap on the step (u, v, a at both ends) screens for an extremum that
 *    crosses 0 inside one step (docs/problems.md P7, grazing contacts); the crossing is then
 *    confirmed on re-integrated states.
 *  - At an event the unilateral contacts touching within tolerance are resolved together by
 *    Newton's law at the velocity level, 0 <= g'+ + e g'- _|_ P >= 0: an impulse LCP on the
 *    Delassus matrix W = G M^-1 G^T (consistent mass through martello_eval_solve_mass),
 *    momentum conserved. An accumulation of impacts (the policy of docs/impulse.md §4) makes the contact a bilateral
 *    constraint whose multiplier is the contact force; an acceleration-level LCP decides which
 *    contacts stay closed. Delassus matrices, LCPs, projections and the accumulation policy
 *    are the shared impulse problem (fortran/impulse.f90, c/martello_internal.h). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include "martello.h"
#include "martello_internal.h"

/* What a contact waits for. After an event the state is the far end of the final bracket
 * (within event_tol of the root), so the status committed there is the new one. */
enum { ROOT_IMPACT,      /* unilateral gap closing: delta >= 0                     */
       ROOT_ONSET,       /* penalty gap: delta > 0 (the law's force starts)         */
       ROOT_SEPARATION,  /* penalty gap: delta <= 0                                */
       ROOT_RELEASE,     /* persistent contact: multiplier P below -tolerance       */
       ROOT_SWITCH };    /* a law's branch left: switch g > 0 (index nc + slot)     */

/* events without time advancing before the run is declared stuck */
#define MAX_EVENTS_AT_ONCE 1000
/* two stops closer than this many units of rounding of their time are one (ed_integrate) */
#define STOP_ROUNDING (16.0 * DBL_EPSILON)

typedef struct {
  martello_model *model;
  martello_run *run;
  martello_observer *obs;         /* what the run measures */
  martello_eval *ev;
  int kind, n, nc, nu;            /* integrator; nodes, contacts, unilateral contacts */
  size_t dim;                     /* 2n + 4 */
  double t_end, dt_out, rtol, atol, event_tol, h_max;
  int every;
  /* topology */
  double *mass, *gap, *e;
  int *fixed, *scheme, *is_pen, *uni, *inert;
  /* the elements' rows (martello_model_elements): elem all of them, con the contacts' */
  int *el_first, *el_node;
  double *el_coef;
  martello_rows elem, con;
  double *Cm;                     /* M^-1 B_j^T of unilateral contact j (B_j = e_b - e_a, the
                                     impulse door's sign): column uni[j] */
  /* ODE */
  gsl_odeiv2_system sys;
  gsl_odeiv2_driver *drv;         /* the main stepper with its control and evolve */
  gsl_odeiv2_step *rstep;         /* rkf45, rk8pd: one step from the step start */
  gsl_odeiv2_driver *rdrv;        /* msbdf: adaptive rk4imp from the step start */
  double *scale_abs;
  double *y, *y0, *yb, *ybest, *yc, *yerr, *fstart, *f, *f1, *fj, *yj, *fint, *fext;
  double *jf0, *jf1, *jf2;         /* ed_jacobian's own RHS values (msbdf, rk4imp) */
  double *jh;                      /* a jerk projected for the held forces' rates (rates) */
  /* contact kinematics at the step start (0), the step end (1) and the current state */
  double *pen0, *rate0, *acc0, *pen1, *rate1, *acc1, *pen, *rate, *force;
  double *lam, *lam0, *lam1, *lamtol;
  /* persistent (held) contacts: the list and W_H factored */
  int nh, *hlist, *held;
  double *Wh, *rh;
  /* impulse problems (c/martello_internal.h): contact lists, W, data and results; hk is the
   * held flag of the persistent-contact rule */
  int *ilist, *hk;
  double *Wl, *ql, *pl, *wl, *sl, *el, *tg;
  martello_accumulation acc;      /* the accumulation rule's phases (c/accumulation.c) */
  /* the switches of the laws' branches (martello_eval_switches), refreshed at every commit */
  int nsw, *sw_el;
  double *sw_al, *sw_be, *sw_ga;
  /* located peaks (c/located_peaks.c): the element quantities and their rates
   * (c/located_peaks.c's packed layout) at the start (0) and end
   * (1) of the smooth stretch and at a probed state (c); node jerks at both ends, the
   * stretch's start time */
  int nl, start_rates;
  double *el0, *el1, *elc, *jk0, *jk1, *fp;
  double t_stretch;
  /* cost counters; kinetic energy taken out by impulses since the last commit */
  long long cnt[MARTELLO_NCOUNTERS];
  double e_impact;
  int rhs_status;                 /* why the RHS stopped GSL */
  double alloc_bytes;             /* the size of the last allocation tried (ALLOC) */
  char msg[512];
} ed_t;

/* ---- helpers --------------------------------------------------------------------------- */

/* An allocation failed: the library's out-of-memory line for what (for the run's n nodes
 * and nc contacts) and bytes (< 0: allocated inside GSL, amount not known). */
static int fail_memory(ed_t *w, const char *what, double bytes, double t) {
  char of[192];
  snprintf(of, sizeof of, "%s for a scene of %d nodes and %d contacts", what, w->n, w->nc);
  martello_memory_message(of, bytes, NULL, w->msg, (int)sizeof w->msg);
  return martello_observer_fail(w->obs, MARTELLO_ERR_MEMORY, t, w->msg);
}

/* The run fails with status at t, saying what; MARTELLO_ERR_MEMORY comes only from the
 * impulse doors (their LCP solver's work arrays) and says so in the out-of-memory line. */
static int fail(ed_t *w, int status, double t, const char *what) {
  if (status == MARTELLO_ERR_MEMORY)
    return fail_memory(w, "the work arrays of the event-driven LCP solver", -1.0, t);
  snprintf(w->msg, sizeof w->msg, "%s (t = %.9e s)", what, t);
  return martello_observer_fail(w->obs, status, t, w->msg);
}

static int fail_eval(ed_t *w, int status, double t) {
  if (status == MARTELLO_ERR_DIVERGED)
    return martello_observer_fail(w->obs, MARTELLO_ERR_DIVERGED, t, NULL);
  return fail(w, status, t, status == MARTELLO_ERR_SINGULAR
                                ? "event-driven: the mass matrix is singular on the free nodes"
                                : "event-driven: the force evaluation failed");
}

/* G_j x: contact j's row (x_a - x_b for a node pair). */
static double gdot(const ed_t *w, int j, const double *x) {
  return martello_rows_dot(&w->con, j, x);
}

/* The impulse door's topology arguments (c/martello_internal.h): rows and columns in Cm. */
#define TOPOLOGY(w) &(w)->con, (w)->uni, (w)->Cm

static int all_finite(const double *x, size_t n) {
  size_t i;
  for (i = 0; i < n; i++)
    if (!isfinite(x[i])) return 0;
  return 1;
}

/* sum |coef x| over the row: the magnitude from which G_j x is computed. */
static double node_sum(const ed_t *w, int j, const double *x) {
  return martello_rows_abs(&w->con, j, x);
}

/* |u_a| + |u_b| + |gap|: the magnitude from which the gap is computed. */
static double gap_scale(const ed_t *w, int j, const double *u) {
  return node_sum(w, j, u) + fabs(w->gap[j]);
}

/* A unilateral contact within this of a zero gap touches: the rounding of the gap plus the
 * absolute integration tolerance. */
static double gap_tol(const ed_t *w, int j, const double *u) {
  return 16.0 * DBL_EPSILON * gap_scale(w, j, u) + w->atol;
}

/* The value of switch slot s on the state y: g > 0 once its branch is left. */
static double switch_value(const ed_t *w, int s, const double *y) {
  const int e = w->sw_el[s];
  double du = 0.0, dv = 0.0;
  if (e >= 0) { du = martello_rows_dot(&w->elem, e, y); dv = martello_rows_dot(&w->elem, e, y + w->n); }
  return w->sw_al[s] * du + w->sw_be[s] * dv + w->sw_ga[s];
}

/* The rounding of switch s on y: a value within it is on the surface, not past it (a branch
 * just entered starts there). */
static double switch_rounding(const ed_t *w, int s, const double *y) {
  const int e = w->sw_el[s];
  double su = 0.0, sv = 0.0;
  if (e >= 0) { su = martello_rows_abs(&w->elem, e, y); sv = martello_rows_abs(&w->elem, e, y + w->n); }
  return 16.0 * DBL_EPSILON * (fabs(w->sw_al[s]) * su + fabs(w->sw_be[s]) * sv + fabs(w->sw_ga[s]));
}

static int switch_active(const ed_t *w, int s) {
  return w->sw_al[s] != 0.0 || w->sw_be[s] != 0.0;
}

/* ---- the right-hand side --------------------------------------------------------------- */

/* Accelerations with the held contacts as bilateral constraints: the projection onto
 * B_H a = 0, a += M^-1 B_H^T P_H with W_H P_H = -B_H a; P (compression > 0) is the
 * multiplier. */
static int constrain(ed_t *w, double *a) {
  int k, st;
  st = martello_impulse_project(w->n, w->nh, w->hlist, TOPOLOGY(w), w->Wh, NULL, a, w->rh);
  for (k = 0; k < w->nh; k++) w->lam[w->hlist[k]] = w->rh[k];
  return st;
}

/* y' = [v; a; f_ext.v; f_int.v; link and contact power]. GSL_EBADFUNC stops GSL; the
 * reason is in w->rhs_status. */
static int ed_rhs(double t, const double y[], double dydt[], void *params) {
  ed_t *w = params;
  const int n = w->n;
  const double *u = y, *v = y + n;
  double *a = dydt + n, power[5];
  int i, st;
  w->cnt[MARTELLO_COUNTER_RESIDUAL_EVALUATIONS]++;
  st = martello_eval_forces(w->ev, t, u, v, w->fint, w->fext);
  if (st == MARTELLO_OK) st = martello_eval_power(w->ev, power);
  if (st == MARTELLO_OK) {
    for (i = 0; i < n; i++) a[i] = w->fext[i] - w->fint[i];
    st = martello_eval_solve_mass(w->ev, a);
  }
  if (st != MARTELLO_OK) {
    w->rhs_status = st;
    return GSL_EBADFUNC;
  }
  if (w->nh > 0 && (st = constrain(w, a)) != MARTELLO_OK) {
    w->rhs_status = st;
    return GSL_EBADFUNC;
  }
  for (i = 0; i < n; i++) dydt[i] = w->fixed[i] ? 0.0 : v[i];
  dydt[2 * n] = power[0];
  dydt[2 * n + 1] = power[1];
  dydt[2 * n + 2] = power[3];
  dydt[2 * n + 3] = power[4];
  if (!all_finite(dydt, w->dim)) {
    w->rhs_status = MARTELLO_ERR_DIVERGED;
    return GSL_EBADFUNC;
  }
  return GSL_SUCCESS;
}

/* Jacobian for msbdf and rk4imp: forward differences of the RHS (central ones where a
 * component and its rate are both 0), dense, row-major dfdy[i*dim + j] (GSL's layout); 2n + 2
 * RHS evaluations (one more per such component); u' = v is set exactly. Its RHS values have
 * buffers of their own (jf0, jf1, jf2): rk4imp calls it while a step's end is held in
 * f1 (the event and peak location re-integrate), and a rate taken from a clobbered f1 missed
 * the |v| and |a| peaks of msbdf whenever an extremum of u was located in the same step. */
static int ed_jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params) {
  ed_t *w = params;
  const size_t n = (size_t)w->n, dim = w->dim;
  const double sq = sqrt(DBL_EPSILON);
  double umax = 0.0, vmax = 0.0, ht;
  size_t i, j;
  w->cnt[MARTELLO_COUNTER_JACOBIAN_EVALUATIONS]++;
  if (ed_rhs(t, y, w->jf0, w) != GSL_SUCCESS) return GSL_EBADFUNC;
  for (i = 0; i < n; i++) {
    umax = fmax(umax, fabs(y[i]));
    vmax = fmax(vmax, fabs(y[n + i]));
  }
  memset(dfdy, 0, dim * dim * sizeof *dfdy);
  memcpy(w->yj, y, dim * sizeof *y);
  for (j = 0; j < 2 * n; j++) {
    double step, hh;
    if (w->fixed[j % n]) continue;
    step = sq * fmax(fmax(fabs(y[j]), 1e-3 * (j < n ? umax : vmax)), w->atol);
    if (y[j] == 0.0 && w->jf0[j] == 0.0) {
      /* no direction to step away from (a scene starting at rest: y_j and its rate are 0 in
       * the scene and in its mirror image, whose zeros are not negated): the central
       * difference, odd in the step, is the mirrored scene's column negated to the bit (a
       * forward one is its backward difference there: P8 at rest moved 1e-10 – 1e-9 relative,
       * docs/invariance.md) */
      w->yj[j] = step;
      if (ed_rhs(t, w->yj, w->jf1, w) != GSL_SUCCESS) return GSL_EBADFUNC;
      w->yj[j] = -step;
      if (ed_rhs(t, w->yj, w->jf2, w) != GSL_SUCCESS) return GSL_EBADFUNC;
      w->yj[j] = y[j];
      for (i = n; i < dim; i++) dfdy[i * dim + j] = (w->jf1[i] - w->jf2[i]) / (2.0 * step);
      continue;
    }
    /* away from zero along y_j (along its rate where y_j is 0): the mirrored state (y -> -y)
     * differences the mirrored way, so that a mirrored scene runs the mirrored steps to the
     * bit (docs/invariance.md) */
    w->yj[j] = y[j] + copysign(step, y[j] != 0.0 ? y[j] : w->jf0[j]);
    hh = w->yj[j] - y[j];
    if (ed_rhs(t, w->yj, w->jf1, w) != GSL_SUCCESS) return GSL_EBADFUNC;
    w->yj[j] = y[j];
    for (i = n; i < dim; i++) dfdy[i * dim + j] = (w->jf1[i] - w->jf0[i]) / hh;
  }
  for (i = 0; i < n; i++)
    if (!w->fixed[i]) dfdy[i * dim + n + i] = 1.0;
  ht = sq * fmax(fabs(t), w->dt_out);
  if (ed_rhs(t + ht, y, w->jf1, w) != GSL_SUCCESS) return GSL_EBADFUNC;
  for (i = 0; i < dim; i++) dfdt[i] = (w->jf1[i] - w->jf0[i]) / ht;
  return GSL_SUCCESS;
}

/* The RHS at (t, y) into f, the multipliers of the held contacts into lam (0 elsewhere). */
static int eval_point(ed_t *w, double t, const double *y, double *f, double *lam) {
  if (ed_rhs(t, y, f, w) != GSL_SUCCESS) return w->rhs_status;
  if (lam) {
    int k;
    for (k = 0; k < w->nc; k++) lam[k] = 0.0;
    for (k = 0; k < w->nh; k++) lam[w->hlist[k]] = w->lam[w->hlist[k]];
  }
  return MARTELLO_OK;
}

/* Gap, rate and (with a) second derivative of every contact. */
static void kinematics(const ed_t *w, const double *y, const double *a, double *pen, double *rate,
                       double *acc) {
  int j;
  for (j = 0; j < w->nc; j++) {
    pen[j] = gdot(w, j, y) - w->gap[j];
    rate[j] = gdot(w, j, y + w->n);
    if (acc) acc[j] = gdot(w, j, a);
  }
}

/* ---- persistent contacts --------------------------------------------------------------- */

static int factor_held(ed_t *w, double t) {
  w->cnt[MARTELLO_COUNTER_FACTORIZATIONS]++;
  if (martello_impulse_factor(w->n, w->nh, w->hlist, TOPOLOGY(w), w->Wh) != MARTELLO_OK)
    return fail(w, MARTELLO_ERR_SINGULAR, t,
                "event-driven: the persistent contacts are redundant (singular Delassus matrix "
                "G M^-1 G^T)");
  return MARTELLO_OK;
}

/* Which of the contacts in list[0..m) (all at zero gap and zero gap rate) stay closed: the
 * persistent-contact rule of docs/impulse.md §3, the acceleration-level LCP on the free
 * accelerations (martello_impulse_contact_forces): a contact stays held unless the solution
 * opens it. Contacts leaving the held set close their phase at t; entering ones open one
 * that starts at their predicted accumulation time t_hold. */
static int update_held(ed_t *w, double t, const int *list, int m) {
  int k, st, piv, nh_old = w->nh;
  w->nh = 0;
  st = eval_point(w, t, w->y, w->f, NULL);   /* free accelerations */
  w->nh = nh_old;
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  st = martello_impulse_contact_forces(w->n, m, list, TOPOLOGY(w), w->f + w->n, w->pl, w->hk,
                                       &piv);
  w->cnt[MARTELLO_COUNTER_FACTORIZATIONS] += piv;   /* Lemke pivots: rank-one updates of the basis */
  if (st != MARTELLO_OK)
    return fail(w, st, t, st == MARTELLO_ERR_SINGULAR
                ? "event-driven: contacts held together are redundant (singular Delassus matrix)"
                : "event-driven: the contact-force LCP did not converge");
  for (k = 0; k < w->nc; k++) w->sl[k] = w->wl[k] = 0.0;
  for (k = 0; k < m; k++) {
    w->sl[list[k]] = w->pl[k];
    w->wl[list[k]] = w->hk[k];   /* held flag per contact */
  }
  for (k = 0; k < w->nh; k++) {
    int j = w->hlist[k];
    if (w->wl[j] != 0.0) continue;
    martello_accumulation_release(&w->acc, w->obs, j, t, gdot(w, j, w->y + w->n));
    w->held[j] = 0;
    w->cnt[MARTELLO_COUNTER_EVENTS]++;
  }
  w->nh = 0;
  for (k = 0; k < w->nc; k++) {
    if (w->wl[k] == 0.0) continue;
    w->hlist[w->nh++] = k;
    if (!w->held[k]) {
      double fs = martello_rows_abs(&w->con, k, w->fext) + martello_rows_abs(&w->con, k, w->fint);
      w->held[k] = 1;
      martello_accumulation_hold(&w->acc, w->obs, k);
      /* a release needs a tension beyond the rounding of the forces at the contact */
      w->lamtol[k] = 1e3 * DBL_EPSILON * fmax(fs, w->sl[k]);
      w->cnt[MARTELLO_COUNTER_EVENTS]++;
    }
  }
  return factor_held(w, t);
}

/* Put the contacts in list on gap = 0 and gap rate = 0 by the mass-weighted projection
 * (martello_impulse_project: B v = 0, then B u = -gap); the kinetic energy removed (what the
 * remaining micro-impacts of an accumulation would dissipate) goes to E_IMPACT. */
static int project(ed_t *w, double t, const int *list, int m) {
  int k, st;
  double *u = w->y, *v = w->y + w->n, de = 0.0;
  w->cnt[MARTELLO_COUNTER_FACTORIZATIONS]++;
  if (martello_impulse_factor(w->n, m, list, TOPOLOGY(w), w->Wl) != MARTELLO_OK)
    return fail(w, MARTELLO_ERR_SINGULAR, t,
                "event-driven: contacts held together are redundant (singular Delassus matrix)");
  for (k = 0; k < m; k++) {
    w->ql[k] = gdot(w, list[k], v);
    w->tg[k] = -w->gap[list[k]];            /* B u = u_b - u_a = -gap: delta = 0 */
  }
  st = martello_impulse_project(w->n, m, list, TOPOLOGY(w), w->Wl, NULL, v, w->pl);
  if (st == MARTELLO_OK)
    st = martello_impulse_project(w->n, m, list, TOPOLOGY(w), w->Wl, w->tg, u, w->wl);
  if (st != MARTELLO_OK) return fail(w, st, t, "event-driven: the contact projection failed");
  for (k = 0; k < m; k++) de += 0.5 * w->pl[k] * w->ql[k];   /* 1/2 P (g'- + g'+), g'+ = 0 */
  w->e_impact += de;
  return MARTELLO_OK;
}

/* ---- impacts and accumulations ---------------------------------------------------------- */

/* Newton's law on the touching unilateral contacts at once (martello_impulse_newton,
 * docs/impulse.md §2; a held contact with e = 0), momentum conserved. Impacts on free
 * contacts are events. */
static int impacts(ed_t *w, double t, int *n_impacts) {
  int j, k, m = 0, st, piv, approaching = 0;
  double *u = w->y, *v = w->y + w->n;
  *n_impacts = 0;
  for (j = 0; j < w->nc; j++) {
    double d, r;
    if (w->is_pen[j] || w->inert[j]) continue;
    d = gdot(w, j, u) - w->gap[j];
    r = gdot(w, j, v);
    if (!w->held[j] && d < -(gap_tol(w, j, u) + w->event_tol * fmax(r, 0.0))) continue;
    w->ilist[m] = j;
    w->sl[m] = r;
    w->el[m] = w->held[j] ? 0.0 : w->e[j];
    /* an approach beyond the rounding of v_a - v_b calls for impulses (a contact released
     * with zero relative speed is not an impact) */
    if (r > 64.0 * DBL_EPSILON * node_sum(w, j, v)) approaching = 1;
    m++;
  }
  if (!approaching) return MARTELLO_OK;
  st = martello_impulse_newton(w->n, m, w->ilist, TOPOLOGY(w), w->el, v, w->pl, &piv);
  w->cnt[MARTELLO_COUNTER_FACTORIZATIONS] += piv;   /* Lemke pivots */
  if (st != MARTELLO_OK)
    return fail(w, st, t, st == MARTELLO_ERR_SINGULAR
                ? "event-driven: simultaneous impacts on redundant contacts (singular Delassus "
                  "matrix)"
                : "event-driven: the impact LCP did not converge");
  for (k = 0; k < m; k++) {
    int jj = w->ilist[k];
    double r_after;
    if (w->pl[k] == 0.0) continue;
    r_after = gdot(w, jj, v);
    /* kinetic energy lost, 1/2 (v- + v+)^T G^T P: exact to rounding, no cancellation */
    w->e_impact += 0.5 * w->pl[k] * (w->sl[k] + r_after);
    if (w->held[jj]) continue;   /* a persistent contact takes its share without an event */
    martello_observer_add_impact(w->obs, jj, t, w->sl[k], r_after,
                                 fmax(gdot(w, jj, u) - w->gap[jj], 0.0), w->pl[k]);
    w->cnt[MARTELLO_COUNTER_EVENTS]++;
    (*n_impacts)++;
  }
  return MARTELLO_OK;
}

/* Contact j's impacts accumulate by the rule of every integrator (docs/impulse.md §4) at the
 * state w->y (its RHS in w->f), leaving at speed s while pressed by acc: its events are
 * located to event_tol, its gap and gap rate known to the integration tolerance a step of the
 * node states they come from (with their rounding); msbdf restarts at order 1 after every
 * event. The change of acc over the next flight tau = 2 s/acc is read at the end of a tangent
 * step of length tau. held: decided for a contact already persistent, whose phase start stays
 * (the held set's own response, no change). */
static int accumulates(ed_t *w, int j, double s, double acc, double t, int held, int *st) {
  const double *y = w->y;
  const double d_res = gap_tol(w, j, y) + w->rtol * node_sum(w, j, y);
  const double v_res = w->atol + (w->rtol + 64.0 * DBL_EPSILON) * node_sum(w, j, y + w->n);
  const int restarts = w->kind == MARTELLO_INT_MSBDF;
  double t_inf, da = 0.0;
  size_t i;
  *st = MARTELLO_OK;
  if (held)
    return martello_impulse_accumulation(w->e[j], s, acc, 0.0, t, w->event_tol, d_res, v_res,
                                         restarts, &t_inf);
  if (s > 0.0 && acc > 0.0) {
    const double tau = 2.0 * s / acc;
    for (i = 0; i < w->dim; i++) w->yc[i] = y[i] + tau * w->f[i];
    if ((*st = eval_point(w, t + tau, w->yc, w->fj, NULL)) != MARTELLO_OK) return 0;
    da = gdot(w, j, w->fj + w->n) - acc;
  }
  return martello_accumulation_decide(&w->acc, j, w->e[j], s, acc, da, t, w->event_tol, d_res,
                                      v_res, restarts);
}

/* After the impacts: touching contacts whose impacts accumulate (accumulates(): no rebound, or
 * a next flight below the resolution, docs/impulse.md §4), or that touch at rest while pressed,
 * join the held set, their phase starting at the predicted accumulation point; held contacts
 * that an impulse set flying leave it unless their new sequence accumulates too. A free
 * contact is a candidate only when the free system presses it (g'' > 0): one that is not
 * pressed would leave the held set at once. */
static int accumulations(ed_t *w, double t, int *changed) {
  int j, k, l, m = 0, st;
  double *u = w->y, *v = w->y + w->n;
  *changed = 0;
  st = eval_point(w, t, w->y, w->f, w->lam1);
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  if (w->nh > 0)
    st = martello_impulse_delassus(w->n, w->nh, w->hlist, TOPOLOGY(w), w->Wl);
  if (st != MARTELLO_OK)
    return fail(w, st, t, "event-driven: the Delassus matrix of the held contacts failed");
  for (j = 0; j < w->nc; j++) {
    double s, acc;
    if (w->is_pen[j] || w->inert[j]) continue;
    s = fmax(-gdot(w, j, v), 0.0);
    if (w->held[j]) {
      /* the free system presses a held contact with (W_H P_H)_j */
      for (k = 0; k < w->nh && w->hlist[k] != j; k++) continue;
      for (acc = 0.0, l = 0; l < w->nh; l++) acc += w->Wl[k + w->nh * l] * w->lam1[w->hlist[l]];
      if (accumulates(w, j, s, acc, t, 1, &st)) {
        w->ilist[m++] = j;
      } else {
        *changed = 1;
      }
      continue;
    }
    if (gdot(w, j, u) - w->gap[j] < -gap_tol(w, j, u)) continue;
    acc = gdot(w, j, w->f + w->n);
    if (!(acc > 0.0)) continue;
    if (!accumulates(w, j, s, acc, t, 0, &st)) {
      if (st != MARTELLO_OK) return fail_eval(w, st, t);
      continue;
    }
    w->ilist[m++] = j;
    *changed = 1;
  }
  if (!*changed) return MARTELLO_OK;
  if (m > 0) {
    st = project(w, t, w->ilist, m);
    if (st != MARTELLO_OK) return st;
  }
  return update_held(w, t, w->ilist, m);
}

/* Everything that happens at time t with the state w->y: penalty phases opening or
 * closing, persistent contacts released, impacts, accumulations. */
static int process_events(ed_t *w, double t) {
  int j, st, ni, changed;
  st = eval_point(w, t, w->y, w->f, w->lam1);
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  kinematics(w, w->y, w->f + w->n, w->pen, w->rate, NULL);
  for (j = 0; j < w->nc; j++) {
    if (!w->is_pen[j] || w->inert[j]) continue;
    if (w->pen[j] > 0.0 && !martello_observer_in_phase(w->obs, j)) {
      martello_observer_set_phase(w->obs, j, 1, t, w->rate[j]);
      w->cnt[MARTELLO_COUNTER_EVENTS]++;
    } else if (!(w->pen[j] > 0.0) && martello_observer_in_phase(w->obs, j)) {
      martello_observer_set_phase(w->obs, j, 0, t, w->rate[j]);
      w->cnt[MARTELLO_COUNTER_EVENTS]++;
    }
  }
  for (j = 0; j < w->nh; j++)
    if (w->lam1[w->hlist[j]] < -w->lamtol[w->hlist[j]]) break;
  if (j < w->nh) {   /* a persistent contact turned tensile: decide the held set again */
    int m = w->nh;
    memcpy(w->ilist, w->hlist, (size_t)m * sizeof *w->ilist);
    st = update_held(w, t, w->ilist, m);
    if (st != MARTELLO_OK) return st;
  }
  st = impacts(w, t, &ni);
  if (st != MARTELLO_OK) return st;
  return accumulations(w, t, &changed);
}

/* ---- event location -------------------------------------------------------------------- */

/* y(t0 + tau) from the step start w->y0 into yout: the stepper's one-step method with the
 * shorter step (rkf45, rk8pd: tau = h reproduces the accepted step), or for msbdf an
 * adaptive rk4imp run. */
static int reintegrate(ed_t *w, double t0, double tau, double *yout) {
  int st = GSL_SUCCESS;
  memcpy(yout, w->y0, w->dim * sizeof *yout);
  if (tau <= 0.0) return MARTELLO_OK;
  if (w->rstep != NULL) {
    st = gsl_odeiv2_step_apply(w->rstep, t0, tau, yout, w->yerr, w->fstart, NULL, &w->sys);
  } else {
    double t = t0;
    gsl_odeiv2_driver_reset_hstart(w->rdrv, tau);
    st = gsl_odeiv2_driver_apply(w->rdrv, &t, t0 + tau, yout);
  }
  if (st == GSL_EBADFUNC) return fail_eval(w, w->rhs_status, t0 + tau);
  if (st != GSL_SUCCESS) {
    snprintf(w->msg, sizeof w->msg,
             "event-driven: re-integration for event location failed at t = %.9e s: "
             "gsl: %s (status %d)", t0 + tau, gsl_strerror(st), st);
    return martello_observer_fail(w->obs, MARTELLO_ERR_EXTERNAL, t0 + tau, w->msg);
  }
  return MARTELLO_OK;
}

/* The root function of contact j on a state: its sign says on which side of the event the
 * state lies; see after(). Gap types also give their rate in the same sign convention. */
static int root_value(ed_t *w, int j, int type, double t, const double *y, double *g,
                      double *rate) {
  const double sgn = type == ROOT_SEPARATION ? -1.0 : 1.0;
  w->cnt[MARTELLO_COUNTER_ROOT_EVALUATIONS]++;
  if (type == ROOT_SWITCH) {
    *g = switch_value(w, j - w->nc, y);
    if (rate) *rate = 0.0;
    return MARTELLO_OK;
  }
  if (type == ROOT_RELEASE) {   /* (the step end's RHS in f1 stays) */
    int st = eval_point(w, t, y, w->fj, NULL);
    if (st != MARTELLO_OK) return fail_eval(w, st, t);
    *g = -(w->lam[j] + w->lamtol[j]);
    if (rate) *rate = 0.0;
    return MARTELLO_OK;
  }
  *g = sgn * (gdot(w, j, y) - w->gap[j]);
  if (rate) *rate = sgn * gdot(w, j, y + w->n);
  return MARTELLO_OK;
}

static int after(int type, double g) {
  return (type == ROOT_ONSET || type == ROOT_RELEASE || type == ROOT_SWITCH) ? g > 0.0 : g >= 0.0;
}

/* Shrink the bracket [ta, tb] (before/after the event) to event_tol by Illinois iterations,
 * bisecting when three iterations have not halved it. yb holds the state at tb throughout. */
static int illinois(ed_t *w, int j, int type, double t0, double ta, double ga, double *tb,
                    double gb, double *yb) {
  int side = 0, it, stall = 0, st;
  double width = *tb - ta;
  for (it = 0; it < 300 && *tb - ta > w->event_tol; it++) {
    double tm, gm;
    tm = (stall >= 3 || !(gb - ga > 0.0)) ? 0.5 * (ta + *tb) : *tb - gb * (*tb - ta) / (gb - ga);
    tm = fmin(fmax(tm, ta + 0.25 * w->event_tol), *tb - 0.25 * w->event_tol);
    st = reintegrate(w, t0, tm - t0, w->yc);
    if (st != MARTELLO_OK) return st;
    st = root_value(w, j, type, tm, w->yc, &gm, NULL);
    if (st != MARTELLO_OK) return st;
    if (after(type, gm)) {
      *tb = tm; gb = gm;
      memcpy(yb, w->yc, w->dim * sizeof *yb);
      if (side == 1) ga *= 0.5;
      side = 1;
    } else {
      ta = tm; ga = gm;
      if (side == -1) gb *= 0.5;
      side = -1;
    }
    if (*tb - ta <= 0.5 * width) {
      width = *tb - ta;
      stall = 0;
    } else {
      stall++;
    }
  }
  return MARTELLO_OK;
}

/* Quintic Hermite interpolant of a scalar on a step of length h in theta in [0, 1] (value,
 * rate, second derivative at both ends), and the cubic one (value and rate). */
typedef struct { double c[6], k[4]; } hermite_t;

static void hermite_build(hermite_t *p, double h, double y0, double r0, double q0, double y1,
                          double r1, double q1) {
  const double d0 = h * r0, d1 = h * r1, s0 = h * h * q0, s1 = h * h * q1;
  const double A = y1 - y0 - d0 - 0.5 * s0, B = d1 - d0 - s0, C = s1 - s0;
  p->c[0] = y0; p->c[1] = d0; p->c[2] = 0.5 * s0;
  p->c[3] = 10.0 * A - 4.0 * B + 0.5 * C;
  p->c[4] = -15.0 * A + 7.0 * B - C;
  p->c[5] = 6.0 * A - 3.0 * B + 0.5 * C;
  p->k[0] = y0; p->k[1] = d0;
  p->k[2] = 3.0 * (y1 - y0) - 2.0 * d0 - d1;
  p->k[3] = 2.0 * (y0 - y1) + d0 + d1;
}

static double hermite_value(const hermite_t *p, double x) {
  return p->c[0] + x * (p->c[1] + x * (p->c[2] + x * (p->c[3] + x * (p->c[4] + x * p->c[5]))));
}

static double hermite_rate(const hermite_t *p, double x) {
  return p->c[1] +
         x * (2.0 * p->c[2] + x * (3.0 * p->c[3] + x * (4.0 * p->c[4] + x * 5.0 * p->c[5])));
}

/* The interior extremum of the quintic (its rate changes sign on [0, 1]), by bisection; the
 * quintic-minus-cubic difference there serves as its error estimate. */
static void hermite_extremum(const hermite_t *p, double *value, double *err) {
  double lo = 0.0, hi = 1.0, x;
  const int rising = hermite_rate(p, 0.0) > 0.0;
  int it;
  for (it = 0; it < 60; it++) {
    double mid = 0.5 * (lo + hi);
    if ((hermite_rate(p, mid) > 0.0) == rising) lo = mid; else hi = mid;
  }
  x = 0.5 * (lo + hi);
  *value = hermite_value(p, x);
  *err = fabs(*value - (p->k[0] + x * (p->k[1] + x * (p->k[2] + x * p->k[3]))));
}

/* Search re-integrated states of the step for one on the wanted side of the event (want_after
 * = 1: past it; 0: before it), iterating towards the extremum of the gap (the root of its
 * rate, which changes sign between r0 at t0 and r1 at t1). Returns 1 with the time, root
 * value (and, for want_after, the state in yb) when found, 0 otherwise. */
static int search_extremum(ed_t *w, int j, int type, double t0, double t1, double r0, double r1,
                           int want_after, double *tf, double *gf, double *yb) {
  double ta = t0, tc = t1, ra = r0, rc = r1;
  int it, side = 0, st;
  for (it = 0; it < 300 && tc - ta > w->event_tol; it++) {
    double tm = (it % 3 == 2 || !(fabs(rc - ra) > 0.0)) ? 0.5 * (ta + tc)
                                                          : tc - rc * (tc - ta) / (rc - ra);
    double g, rm;
    tm = fmin(fmax(tm, ta + 0.25 * w->event_tol), tc - 0.25 * w->event_tol);
    st = reintegrate(w, t0, tm - t0, w->yc);
    if (st != MARTELLO_OK) return st;
    st = root_value(w, j, type, tm, w->yc, &g, &rm);
    if (st != MARTELLO_OK) return st;
    if (after(type, g) == want_after) {
      *tf = tm; *gf = g;
      if (yb) memcpy(yb, w->yc, w->dim * sizeof *yb);
      return 1;
    }
    if ((rm > 0.0) == (ra > 0.0)) {
      ta = tm; ra = rm;
      if (side == -1) rc *= 0.5;
      side = -1;
    } else {
      tc = tm; rc = rm;
      if (side == 1) ra *= 0.5;
      side = 1;
    }
  }
  return 0;
}

/* Samples of the step's interpolant screened for a switch crossed and re-crossed inside it
 * (grazing): the switches are affine in the relative motion of two nodes, whose quintic
 * Hermite interpolant (u, v, a at both ends) gives the switch along the step. */
#define GRAZING_SAMPLES 32

/* The bracket of switch slot s in the step [t0, t1]: 1 with the value before at t0 (*ga)
 * and past at *tb (*gb, state in w->yb), 0 if it is not crossed, < 0 on failure. */
static int bracket_switch(ed_t *w, int s, double t0, double t1, double *ga, double *tb,
                          double *gb) {
  const int n = w->n, e = w->sw_el[s];
  const double h = t1 - t0;
  double x[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, best = -HUGE_VAL, xbest = 0.0, tol;
  hermite_t p;
  int i, st;
  *ga = switch_value(w, s, w->y0);
  *gb = switch_value(w, s, w->y);
  /* the commit chose the branch at the step start (a value past 0 there is the rounding of
   * a switch just crossed, or a branch chosen from a state past its surface): the start is
   * on the branch's side */
  if (*gb > switch_rounding(w, s, w->y)) {
    memcpy(w->yb, w->y, w->dim * sizeof *w->yb);
    return 1;
  }
  /* du, dv, da at both ends */
  if (e >= 0) {
    const martello_rows *r = &w->elem;
    x[0][0] = martello_rows_dot(r, e, w->y0); x[0][1] = martello_rows_dot(r, e, w->y0 + n);
    x[0][2] = martello_rows_dot(r, e, w->fstart + n);
    x[1][0] = martello_rows_dot(r, e, w->y); x[1][1] = martello_rows_dot(r, e, w->y + n);
    x[1][2] = martello_rows_dot(r, e, w->f1 + n);
  }
  hermite_build(&p, h, x[0][0], x[0][1], x[0][2], x[1][0], x[1][1], x[1][2]);
  for (i = 1; i < GRAZING_SAMPLES; i++) {
    const double th = (double)i / GRAZING_SAMPLES;
    const double g = w->sw_al[s] * hermite_value(&p, th) +
                     w->sw_be[s] * hermite_rate(&p, th) / h + w->sw_ga[s];
    if (g > best) { best = g; xbest = th; }
  }
  /* the interpolant's own error: the position tolerance on both terms */
  tol = (fabs(w->sw_al[s]) + fabs(w->sw_be[s]) / h) *
        (w->atol + w->rtol * (fabs(x[0][0]) + fabs(x[1][0]) + h * (fabs(x[0][1]) + fabs(x[1][1]))));
  if (best + tol < 0.0) return 0;
  *tb = t0 + xbest * h;
  st = reintegrate(w, t0, *tb - t0, w->yb);
  if (st != MARTELLO_OK) return st;
  *gb = switch_value(w, s, w->yb);
  w->cnt[MARTELLO_COUNTER_ROOT_EVALUATIONS]++;
  return *gb > switch_rounding(w, s, w->yb);
}

/* The bracket of contact j's next event in the step [t0, t1], if there is one: before at
 * *ta (value *ga), past at *tb (value *gb, state in w->yb). Returns 1, 0 (none) or < 0. */
static int bracket(ed_t *w, int j, int type, double t0, double t1, double *ta, double *ga,
                   double *tb, double *gb) {
  const double sgn = type == ROOT_SEPARATION ? -1.0 : 1.0;
  double r0, r1;
  int st;
  *ta = t0; *tb = t1;
  if (type == ROOT_SWITCH) return bracket_switch(w, j - w->nc, t0, t1, ga, tb, gb);
  if (type == ROOT_RELEASE) {
    *ga = -(w->lam0[j] + w->lamtol[j]);
    *gb = -(w->lam1[j] + w->lamtol[j]);
    if (after(type, *ga) || !after(type, *gb)) return 0;
    memcpy(w->yb, w->y, w->dim * sizeof *w->yb);
    return 1;
  }
  *ga = sgn * w->pen0[j]; *gb = sgn * w->pen1[j];
  r0 = sgn * w->rate0[j]; r1 = sgn * w->rate1[j];
  if (!after(type, *ga)) {
    hermite_t p;
    double val, err;
    if (after(type, *gb)) {
      memcpy(w->yb, w->y, w->dim * sizeof *w->yb);
      return 1;
    }
    if (!(r0 > 0.0 && r1 < 0.0)) return 0;
    /* both ends before the event, the gap turns inside the step: can it cross? */
    hermite_build(&p, t1 - t0, *ga, r0, sgn * w->acc0[j], *gb, r1, sgn * w->acc1[j]);
    hermite_extremum(&p, &val, &err);
    if (val + 2.0 * err + gap_tol(w, j, w->y0) < 0.0) return 0;
    return search_extremum(w, j, type, t0, t1, r0, r1, 1, tb, gb, w->yb);
  }
  /* touching at the step start (just after an impact or a release): an event only if the
   * gap opened and closed again inside the step */
  if (type != ROOT_IMPACT || !(r0 <= 0.0 && r1 > 0.0 && after(type, *gb))) return 0;
  memcpy(w->yb, w->y, w->dim * sizeof *w->yb);
  st = search_extremum(w, j, type, t0, t1, r0, r1, 0, ta, ga, NULL);
  if (st < 0) return st;
  if (st == 0) *ta = *tb;   /* never opened beyond tolerance: resolve at the step end */
  return 1;
}

/* Contact j's event of the given type in the step, if it comes before the earliest found so
 * far (*found, *best, state in w->ybest): located to event_tol, it becomes the earliest. */
static int consider(ed_t *w, int j, int type, double t0, double t1, int *found, double *best) {
  double ta, tb, ga, gb;
  int st = bracket(w, j, type, t0, t1, &ta, &ga, &tb, &gb);
  if (st <= 0) return st;
  if (*found) {
    if (ta >= *best) return 0;
    if (tb > *best) {   /* an earlier event exists: this one counts only if past by then */
      st = root_value(w, j, type, *best, w->ybest, &gb, NULL);
      if (st != MARTELLO_OK) return st;
      if (!after(type, gb)) return 0;
      tb = *best;
      memcpy(w->yb, w->ybest, w->dim * sizeof *w->yb);
    }
  }
  if (ta < tb) {
    st = illinois(w, j, type, t0, ta, ga, &tb, gb, w->yb);
    if (st != MARTELLO_OK) return st;
  }
  if (!*found || tb < *best) {
    *best = tb;
    *found = 1;
    memcpy(w->ybest, w->yb, w->dim * sizeof *w->ybest);
  }
  return 0;
}

/* The earliest event in the step (t0, y0) -> (t1, y1 = w->y). Returns 1 and moves w->y to
 * the state just past it at *te, 0 if there is none, or a negative status. Events of other
 * contacts within event_tol of it are resolved with it (process_events works on the state). */
static int locate(ed_t *w, double t0, double t1, double *te) {
  int j, st = 0, found = 0;
  double best = t1;
  for (j = 0; j < w->nc && st >= 0; j++) {
    if (w->inert[j]) continue;
    if (w->is_pen[j] && w->pen0[j] > 0.0) {
      /* a penalty contact in contact waits for its separation (its peaks are located inside
       * the steps, c/located_peaks.c) */
      st = consider(w, j, ROOT_SEPARATION, t0, t1, &found, &best);
    } else {
      st = consider(w, j, w->is_pen[j] ? ROOT_ONSET : w->held[j] ? ROOT_RELEASE : ROOT_IMPACT,
                    t0, t1, &found, &best);
    }
  }
  for (j = 0; j < w->nsw && st >= 0; j++)
    if (switch_active(w, j)) st = consider(w, w->nc + j, ROOT_SWITCH, t0, t1, &found, &best);
  if (st < 0) return st;
  if (!found) return 0;
  memcpy(w->y, w->ybest, w->dim * sizeof *w->y);
  *te = best;
  return 1;
}

/* ---- observation ----------------------------------------------------------------------- */

/* The extrema of the node displacements inside the smooth stretch (t0, y0) -> (t1, w->y)
 * (before the events at t1 are processed; its RHS in f1), located on the stepper's own solution
 * (docs/run-layer.md, located extrema): a node whose velocity changes sign gets the root
 * of the derivative of the quintic Hermite interpolant of its u (u, v, a at both ends) as a
 * first guess, one re-integration to it, and the parabolic correction
 * u - v^2/(2a) at t - v/a from the re-integrated state: the error is that of the stepper
 * plus |v|^3 |a'|/a^3, below it wherever the guess is within the interpolant's O(h^5). */
static int node_extrema(ed_t *w, double t0, double t1) {
  const int n = w->n;
  const double h = t1 - t0;
  int i, st;
  if (!(h > 0.0)) return MARTELLO_OK;
  for (i = 0; i < n; i++) {
    const double v0 = w->y0[n + i], v1 = w->y[n + i];
    int is_max, it;
    hermite_t p;
    double lo = 0.0, hi = 1.0, tm, uc, vc, ac, tau;
    if (w->fixed[i]) continue;
    /* a turn inside the velocity's own tolerance is not resolved: its sign is the error's
     * (the precursor of a wave in a lumped rod, u ~ 1e-150 m ahead of the front, turned
     * back and forth with the step sequence and made local maxima of u come and go with
     * the output stops; docs/results.md, u_peak) */
    if (!(fmax(fabs(v0), fabs(v1)) > w->atol)) continue;
    if (v0 > 0.0 && v1 <= 0.0) is_max = 1;
    else if (v0 < 0.0 && v1 >= 0.0) is_max = 0;
    else continue;
    if (v1 == 0.0) {   /* the step ends on it */
      st = martello_observer_extremum(w->obs, i, t1, w->y[i], is_max);
      if (st != MARTELLO_OK) return fail(w, st, t1, "event-driven: martello_observer_extremum failed");
      continue;
    }
    hermite_build(&p, h, w->y0[i], v0, w->fstart[n + i], w->y[i], v1, w->f1[n + i]);
    for (it = 0; it < 60; it++) {
      const double mid = 0.5 * (lo + hi);
      if ((hermite_rate(&p, mid) > 0.0) == (v0 > 0.0)) lo = mid; else hi = mid;
    }
    tm = t0 + 0.5 * (lo + hi) * h;
    st = reintegrate(w, t0, tm - t0, w->yc);
    if (st != MARTELLO_OK) return st;
    st = eval_point(w, tm, w->yc, w->fj, NULL);
    if (st != MARTELLO_OK) return fail_eval(w, st, tm);
    uc = w->yc[i]; vc = w->yc[n + i]; ac = w->fj[n + i];
    tau = (ac != 0.0) ? -vc / ac : 0.0;
    if (fabs(tau) <= h) {
      uc += vc * tau + 0.5 * ac * tau * tau;
      tm += tau;
    }
    st = martello_observer_extremum(w->obs, i, tm, uc, is_max);
    if (st != MARTELLO_OK) return fail(w, st, tm, "event-driven: martello_observer_extremum failed");
  }
  return MARTELLO_OK;
}

/* The rates of the peak quantities at the state (t, y) with accelerations acc: elements into
 * e (c/located_peaks.c's packed layout), node jerks into jerk. */
static int rates(ed_t *w, double t, const double *y, const double *acc, const double *lam,
                 double *e, double *jerk) {
  int k, st = martello_peak_rates(w->ev, t, y, y + w->n, acc, w->nc, w->nl, e, jerk);
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  if (w->nh == 0) return MARTELLO_OK;
  /* a held contact's force is its multiplier P (lam at this state), and its rate the
   * multiplier of the jerk, W_H P' = -B_H j (the constraint is linear, the mass constant):
   * its peaks are located inside the steps like a penalty force's (c/located_peaks.c's
   * layout: the contact forces at 2 nc, their rates at 3 nc) */
  memcpy(w->jh, jerk, (size_t)w->n * sizeof *jerk);
  st = martello_impulse_project(w->n, w->nh, w->hlist, TOPOLOGY(w), w->Wh, NULL, w->jh, w->rh);
  if (st != MARTELLO_OK) return fail(w, st, t, "event-driven: the rate of a held contact's force");
  for (k = 0; k < w->nh; k++) {
    e[2 * w->nc + w->hlist[k]] = lam[w->hlist[k]];
    e[3 * w->nc + w->hlist[k]] = w->rh[k];
  }
  return MARTELLO_OK;
}

/* The probe of c/located_peaks.c: quantity kind of item j at t inside the stretch, on the
 * stepper's own solution (re-integrated from its start). */
static int peak_probe(void *ctx, double t, int kind, int j, double *q, double *r) {
  ed_t *w = ctx;
  const int n = w->n;
  int st = reintegrate(w, w->t_stretch, t - w->t_stretch, w->yc);
  if (st != MARTELLO_OK) return st;
  st = eval_point(w, t, w->yc, w->fj, NULL);
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  if (kind != MARTELLO_PEAK_V &&
      (st = rates(w, t, w->yc, w->fj + n, w->lam, w->elc, w->fp)) != MARTELLO_OK)
    return st;
  martello_peak_pick(kind, j, w->nc, w->nl, w->yc + n, w->fj + n, w->fp, w->elc, q, r);
  return MARTELLO_OK;
}

/* Items without a peak of their own here: fixed nodes, contacts that are not penalty ones
 * or not in a phase (but the force of a held contact, its multiplier). */
static int peak_skip(void *ctx, int kind, int j) {
  ed_t *w = ctx;
  if (kind == MARTELLO_PEAK_V || kind == MARTELLO_PEAK_A) return w->fixed[j];
  if (kind == MARTELLO_PEAK_FORCE && w->held[j]) return 0;
  if (kind == MARTELLO_PEAK_PEN || kind == MARTELLO_PEAK_FORCE)
    return !w->is_pen[j] || !martello_observer_in_phase(w->obs, j);
  return 0;
}

/* The peaks inside the smooth stretch (t0, y0, fstart) -> (t1, w->y, f1), before the events
 * at t1 (docs/run-layer.md, located peaks): every quantity's value and rate at both ends
 * (the start's kept from the last stretch's end when nothing happened there: w->start_rates),
 * then c/located_peaks.c. */
static int located_peaks(ed_t *w, double t0, double t1, int at_event) {
  const int n = w->n;
  martello_peak_ends e;
  int st;
  if (!(t1 - t0 > 0.0)) return MARTELLO_OK;
  if (!w->start_rates &&
      (st = rates(w, t0, w->y0, w->fstart + n, w->lam0, w->el0, w->jk0)) != MARTELLO_OK)
    return st;
  if ((st = rates(w, t1, w->y, w->f1 + n, w->lam1, w->el1, w->jk1)) != MARTELLO_OK) return st;
  memset(&e, 0, sizeof e);
  martello_peak_ends_set(&e, 0, n, w->nc, w->nl, w->y0 + n, w->fstart + n, w->jk0, w->el0);
  martello_peak_ends_set(&e, 1, n, w->nc, w->nl, w->y + n, w->f1 + n, w->jk1, w->el1);
  e.skip = peak_skip;
  w->t_stretch = t0;
  if (at_event && (st = martello_peak_fold_end(w->obs, &e, w)) != MARTELLO_OK) return st;
  return martello_locate_peaks(w->obs, &e, t0, t1, w->rtol, w->event_tol, peak_probe, w);
}

/* After a step: the rates at its end are the next step's start when the state and the laws'
 * branches went on unchanged (no event, no kink of a load there). */
static void keep_end_rates(ed_t *w, int unchanged) {
  double *tmp;
  w->start_rates = unchanged;
  if (!unchanged) return;
  tmp = w->el0; w->el0 = w->el1; w->el1 = tmp;
  tmp = w->jk0; w->jk0 = w->jk1; w->jk1 = tmp;
}

/* Accept the state w->y at t: path-dependent links commit, and the works since the last
 * accepted state go to the observer (w_start: the work integrals y[2n .. 2n+3] there). */
static int commit(ed_t *w, double t, const double *w_start) {
  const double *wk = w->y + 2 * w->n;
  int st = martello_eval_commit(w->ev, w->y, w->y + w->n);
  if (st == MARTELLO_OK && w->nsw > 0)   /* the branches may have changed */
    st = martello_eval_switches(w->ev, w->sw_el, w->sw_al, w->sw_be, w->sw_ga);
  if (st == MARTELLO_OK)
    st = martello_observer_work(w->obs, wk[0] - w_start[0], wk[1] - w_start[1],
                                wk[2] - w_start[2], wk[3] - w_start[3], w->e_impact);
  w->e_impact = 0.0;
  return st == MARTELLO_OK ? st : fail(w, st, t, "event-driven: commit failed");
}

/* A sample of the observer at an accepted (committed) state (the force of a held contact
 * is its multiplier); k: the output grid point t = k dt, or -1. Leaves the RHS in
 * w->fstart and the multipliers in w->lam0: the start of the next step. */
static int observe(ed_t *w, double t, int k) {
  const int n = w->n;
  int j, st;
  st = eval_point(w, t, w->y, w->fstart, w->lam0);
  if (st != MARTELLO_OK) return fail_eval(w, st, t);
  for (j = 0; j < w->nc; j++) w->force[j] = w->held[j] ? w->lam0[j] : 0.0;
  return martello_observer_sample(w->obs, w->ev, t, w->y, w->y + n, w->fstart + n, w->force, k);
}

/* ---- set-up and tear-down -------------------------------------------------------------- */

static void ed_free(ed_t *w) {
  void *bufs[] = {w->mass, w->gap, w->e, w->fixed, w->el_first, w->el_node, w->el_coef, w->scheme, w->is_pen,
                  w->uni, w->inert, w->Cm, w->scale_abs, w->y, w->y0, w->yb, w->ybest, w->yc,
                  w->yerr, w->fstart, w->f, w->f1, w->fj, w->jf0, w->jf1, w->jf2, w->jh, w->yj, w->fint, w->fext,
                  w->pen0, w->rate0, w->acc0, w->pen1, w->rate1, w->acc1, w->pen, w->rate,
                  w->force, w->lam, w->lam0, w->lam1, w->lamtol, w->hlist, w->held, w->Wh,
                  w->rh, w->ilist, w->hk, w->Wl, w->ql, w->pl, w->wl, w->sl, w->el, w->tg, 
                  w->sw_el, w->sw_al, w->sw_be, w->sw_ga, w->el0, w->el1, w->elc,
                  w->jk0, w->jk1, w->fp};
  size_t i;
  for (i = 0; i < sizeof bufs / sizeof bufs[0]; i++) free(bufs[i]);
  if (w->drv) gsl_odeiv2_driver_free(w->drv);
  if (w->rdrv) gsl_odeiv2_driver_free(w->rdrv);
  if (w->rstep) gsl_odeiv2_step_free(w->rstep);
  if (w->ev) martello_eval_free(&w->ev);
  martello_accumulation_free(&w->acc);
}

/* p = calloc(count) (at least one element), its size kept in w->alloc_bytes for the
 * out-of-memory line; true on success */
#define ALLOC(p, count) \
  (w->alloc_bytes = (double)((size_t)(count) > 0 ? (size_t)(count) : 1) * sizeof *(p), \
   (p) = calloc((size_t)(count) > 0 ? (size_t)(count) : 1, sizeof *(p)), (p) != NULL)
/* the out-of-memory line of the ALLOC that failed */
#define FAIL_ALLOC() fail_memory(w, "an array of the event-driven state", w->alloc_bytes, 0.0)

/* Everything the run needs, allocated once before the time loop. */
static int ed_setup(ed_t *w) {
  const int n = w->n, nc = w->nc;
  const size_t dim = (size_t)(2 * n + 4);
  const gsl_odeiv2_step_type *T;
  double h0;
  int j, st, nn, nc_read, ncoup, nl_rows, nterms;
  w->dim = dim;
  if (!(ALLOC(w->mass, n) && ALLOC(w->fixed, n) && ALLOC(w->gap, nc) && ALLOC(w->e, nc) &&
        ALLOC(w->scheme, nc) &&
        ALLOC(w->is_pen, nc) &&
        ALLOC(w->uni, nc) && ALLOC(w->inert, nc)))
    return FAIL_ALLOC();
  /* three distinct outputs: the Fortran dummies are intent(out) and must not alias */
  st = martello_model_topology(w->model, &nn, &nc_read, w->mass, w->fixed, w->scheme, w->gap,
                               w->e, &ncoup);
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_model_topology failed");
  st = martello_model_elements(w->model, &nl_rows, &nterms, NULL, NULL, NULL);
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_model_elements failed");
  if (!(ALLOC(w->el_first, nl_rows + nc + 1) && ALLOC(w->el_node, nterms) && ALLOC(w->el_coef, nterms)))
    return FAIL_ALLOC();
  st = martello_model_elements(w->model, &nl_rows, &nterms, w->el_first, w->el_node, w->el_coef);
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_model_elements failed");
  w->elem.first = w->el_first; w->elem.node = w->el_node; w->elem.coef = w->el_coef;
  w->con = w->elem;
  w->con.first = w->el_first + nl_rows;
  for (j = 0; j < n; j++)
    if (w->mass[j] < 0.0) {
      return martello_observer_fail(w->obs, MARTELLO_ERR_STATE, 0.0,
                                    "event-driven: every node must be set before a run");
    }
  w->nu = 0;
  for (j = 0; j < nc; j++) {
    w->is_pen[j] = w->scheme[j] == MARTELLO_SCHEME_PENALTY;
    w->uni[j] = w->is_pen[j] ? -1 : w->nu++;
    /* Newton's e; a Lagrange contact without one is plastic (e = 0) */
    if (w->e[j] < 0.0) w->e[j] = 0.0;
  }
  if (!(ALLOC(w->Cm, (size_t)n * (size_t)w->nu) && ALLOC(w->scale_abs, dim) && ALLOC(w->y, dim) &&
        ALLOC(w->y0, dim) && ALLOC(w->yb, dim) && ALLOC(w->ybest, dim) && ALLOC(w->yc, dim) &&
        ALLOC(w->yerr, dim) && ALLOC(w->fstart, dim) && ALLOC(w->f, dim) && ALLOC(w->f1, dim) &&
        ALLOC(w->fj, dim) && ALLOC(w->jf0, dim) && ALLOC(w->jf1, dim) && ALLOC(w->jf2, dim) && ALLOC(w->jh, n) && ALLOC(w->yj, dim) && ALLOC(w->fint, n) && ALLOC(w->fext, n) &&
        ALLOC(w->pen0, nc) && ALLOC(w->rate0, nc) && ALLOC(w->acc0, nc) &&
        ALLOC(w->pen1, nc) && ALLOC(w->rate1, nc) && ALLOC(w->acc1, nc) && ALLOC(w->pen, nc) &&
        ALLOC(w->rate, nc) && ALLOC(w->force, nc) && ALLOC(w->lam, nc) && ALLOC(w->lam0, nc) &&
        ALLOC(w->lam1, nc) && ALLOC(w->lamtol, nc) && ALLOC(w->hlist, nc) && ALLOC(w->held, nc) &&
        ALLOC(w->Wh, (size_t)w->nu * (size_t)w->nu) && ALLOC(w->rh, nc) && ALLOC(w->ilist, nc) &&
        ALLOC(w->Wl, (size_t)w->nu * (size_t)w->nu) && ALLOC(w->ql, nc) && ALLOC(w->pl, nc) &&
        ALLOC(w->wl, nc) && ALLOC(w->sl, nc) && ALLOC(w->el, nc) && ALLOC(w->tg, nc) &&
        ALLOC(w->hk, nc)))
    return FAIL_ALLOC();
  if (martello_accumulation_init(&w->acc, nc, w->t_end) != MARTELLO_OK)
    return fail_memory(w, "the accumulation phases of the event-driven run",
                       (double)nc * sizeof(double), 0.0);
  st = martello_eval_create(w->model, &w->ev);
  /* out of memory: the model's message is the line (martello_eval_create) */
  if (st == MARTELLO_ERR_MEMORY) {
    martello_model_message(w->model, w->msg, (int)sizeof w->msg);
    return martello_observer_fail(w->obs, st, 0.0, w->msg);
  }
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_eval_create failed");
  st = martello_eval_link_count(w->ev, &w->nl);
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_eval_link_count failed");
  if (!(ALLOC(w->el0, 4 * (nc + w->nl)) && ALLOC(w->el1, 4 * (nc + w->nl)) &&
        ALLOC(w->elc, 4 * (nc + w->nl)) && ALLOC(w->jk0, n) && ALLOC(w->jk1, n) &&
        ALLOC(w->fp, n)))
    return FAIL_ALLOC();
  /* every switching surface of the laws is an event: hold them on smooth branches */
  st = martello_eval_use_branches(w->ev, &w->nsw);
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_eval_use_branches failed");
  if (!(ALLOC(w->sw_el, w->nsw) && ALLOC(w->sw_al, w->nsw) &&
        ALLOC(w->sw_be, w->nsw) && ALLOC(w->sw_ga, w->nsw)))
    return FAIL_ALLOC();
  if (w->nsw > 0 &&
      martello_eval_switches(w->ev, w->sw_el, w->sw_al, w->sw_be, w->sw_ga) != MARTELLO_OK)
    return fail(w, MARTELLO_ERR_ARGUMENT, 0.0, "event-driven: martello_eval_switches failed");
  /* M^-1 B_j^T of every unilateral contact; a contact between two immovable sides is inert */
  for (j = 0; j < nc; j++) {
    double *c;
    int i;
    /* every term on an immovable node: W_jj = 0 (M is positive definite on the free nodes) */
    w->inert[j] = 1;
    for (i = w->con.first[j]; i < w->con.first[j + 1]; i++)
      if (!w->fixed[w->con.node[i]] && w->con.coef[i] != 0.0) w->inert[j] = 0;
    if (w->is_pen[j]) continue;
    c = w->Cm + (size_t)w->uni[j] * n;
    for (i = 0; i < n; i++) c[i] = 0.0;
    martello_rows_axpy(&w->con, j, -1.0, c);         /* B_j^T = -G_j^T */
    st = martello_eval_solve_mass(w->ev, c);
    if (st != MARTELLO_OK) return fail_eval(w, st, 0.0);
  }
  /* the work integrals are outside the error control: an absolute scale that makes their
   * tolerance irrelevant */
  for (j = 0; j < (int)dim; j++) w->scale_abs[j] = j < 2 * n ? 1.0 : 1e100 / w->atol;
  w->sys.function = ed_rhs;
  w->sys.jacobian = ed_jacobian;
  w->sys.dimension = dim;
  w->sys.params = w;
  T = w->kind == MARTELLO_INT_RKF45 ? gsl_odeiv2_step_rkf45
      : w->kind == MARTELLO_INT_RK8PD ? gsl_odeiv2_step_rk8pd : gsl_odeiv2_step_msbdf;
  h0 = 1e-3 * fmin(w->dt_out * w->every, w->t_end);
  if (w->h_max > 0.0) h0 = fmin(h0, w->h_max);
  w->drv = gsl_odeiv2_driver_alloc_scaled_new(&w->sys, T, h0, w->atol, w->rtol, 1.0, 0.0,
                                              w->scale_abs);
  if (w->drv == NULL) return fail_memory(w, "the GSL driver of the event-driven run", -1.0, 0.0);
  if (w->kind == MARTELLO_INT_MSBDF) {
    w->rdrv = gsl_odeiv2_driver_alloc_scaled_new(&w->sys, gsl_odeiv2_step_rk4imp, h0, w->atol,
                                                 w->rtol, 1.0, 0.0, w->scale_abs);
    if (w->rdrv == NULL)
      return fail_memory(w, "the GSL restart driver of the event-driven run", -1.0, 0.0);
  } else {
    w->rstep = gsl_odeiv2_step_alloc(T, dim);
    if (w->rstep == NULL)
      return fail_memory(w, "the GSL restart stepper of the event-driven run", -1.0, 0.0);
  }
  return MARTELLO_OK;
}

/* What GSL's steppers need beyond the ranges martello_run_set_settings checked. */
static int check_settings(ed_t *w) {
  /* a relative tolerance near the rounding unit cannot be met: the steps would shrink to
   * where the error estimates are rounding noise and the run would crawl */
  if (w->rtol >= 10.0 * DBL_EPSILON) return MARTELLO_OK;
  snprintf(w->msg, sizeof w->msg, "event-driven: rtol must be >= 10 machine epsilons (2.2e-15)");
  return martello_observer_fail(w->obs, MARTELLO_ERR_ARGUMENT, 0.0, w->msg);
}

/* The error of gsl_odeiv2_evolve_apply as a martello status and message. */
static int gsl_failure(ed_t *w, int st, double t, double h) {
  if (st == GSL_EBADFUNC) return fail_eval(w, w->rhs_status, t);
  if (st == GSL_FAILURE) {
    snprintf(w->msg, sizeof w->msg,
             "event-driven: step size underflow at t = %.9e s (h = %.3e s): the stepper cannot "
             "meet rtol = %.3e, atol = %.3e (gsl_odeiv2_evolve_apply: %s)",
             t, h, w->rtol, w->atol, gsl_strerror(st));
    return martello_observer_fail(w->obs, MARTELLO_ERR_STEP_UNDERFLOW, t, w->msg);
  }
  snprintf(w->msg, sizeof w->msg, "event-driven: gsl_odeiv2_evolve_apply failed at t = %.9e s: "
           "%s (gsl status %d)", t, gsl_strerror(st), st);
  return martello_observer_fail(w->obs, MARTELLO_ERR_EXTERNAL, t, w->msg);
}

/* ---- the run --------------------------------------------------------------------------- */

static int ed_integrate(ed_t *w) {
  const int n = w->n;
  const long n_out = (long)ceil(w->t_end / w->dt_out * (1.0 - 1e-12));
  long k_out = 1;
  double t = 0.0, h;
  int st, j, stuck = 0;

  /* initial state; contacts must start open or touching */
  st = martello_model_initial_state(w->model, w->y, w->y + n);
  if (st != MARTELLO_OK)
    return fail(w, st, 0.0, "event-driven: martello_model_initial_state failed");
  for (j = 0; j < n; j++)
    if (w->fixed[j]) w->y[n + j] = 0.0;
  for (j = 0; j < w->nc; j++) {
    double d = gdot(w, j, w->y) - w->gap[j];
    if (!w->is_pen[j] && !w->inert[j] && d > gap_tol(w, j, w->y)) {
      snprintf(w->msg, sizeof w->msg,
               "event-driven: contact %d starts penetrated by %.3e m; a restitution or lagrange "
               "contact must start open or touching (gap >= 0)", j, d);
      return martello_observer_fail(w->obs, MARTELLO_ERR_ARGUMENT, 0.0, w->msg);
    }
  }
  st = martello_observer_begin(w->obs, w->ev, w->y, w->y + n, "tighten rtol and atol");
  if (st == MARTELLO_ERR_MEMORY) return st; /* the observer failed the run with its line */
  if (st != MARTELLO_OK) return fail(w, st, 0.0, "event-driven: martello_observer_begin failed");
  st = process_events(w, 0.0);
  if (st == MARTELLO_OK) st = commit(w, 0.0, w->y + 2 * n);
  if (st == MARTELLO_OK) st = observe(w, 0.0, 0);
  if (st != MARTELLO_OK) return st;

  h = 1e-3 * fmin(w->dt_out * w->every, w->t_end);
  while (t < w->t_end) {
    /* the stops: the recorded grid points t = k dt, k a multiple of every, and t_end (the
     * one meaning of the output interval dt x every, docs/run-layer.md, as on IDA) */
    const long k_grid = k_out * (long)w->every;
    const double t_out = k_grid >= n_out ? w->t_end : (double)k_grid * w->dt_out;
    const double t0 = t;
    unsigned long failed = w->drv->e->failed_steps;
    double hs = (w->h_max > 0.0) ? fmin(h, w->h_max) : h, te, t_stop;
    int ev, k = -1, kink;
    /* a kink of the load is a stop (docs/event-driven.md, time events); one within rounding
     * of an output time (a record sampled at 0.01 s, outputs every 0.015 s: k 0.015 and
     * the sample's time differ by an ulp or two) is the same stop, never a step of an ulp,
     * and a kink restarts the stepper whether or not it is also an output time */
    martello_eval_next_breakpoint(w->ev, t, &t_stop);
    if (t_stop - t <= STOP_ROUNDING * fabs(t)) martello_eval_next_breakpoint(w->ev, t_stop, &t_stop);
    kink = t_stop <= t_out + STOP_ROUNDING * fabs(t_out);
    t_stop = (t_stop < t_out - STOP_ROUNDING * fabs(t_out)) ? t_stop : t_out;
    /* msbdf lowers its order whenever a step is less than half the steps before it (GSL's
     * stability heuristic), and a step cut short by a stop is such a step: with a stop every
     * few steps the order never rises and BDF1's damping takes a few % of the speed a flight
     * at rtol 1e-3 (docs/event-driven.md). The last two steps before a stop share what is
     * left, so that no step is cut below half of the one before. */
    if (w->kind == MARTELLO_INT_MSBDF && t_stop - t < 2.0 * hs && t_stop - t > hs)
      hs = 0.5 * (t_stop - t);
    /* the step start: state, RHS (from observe), gap kinematics */
    memcpy(w->y0, w->y, w->dim * sizeof *w->y);
    kinematics(w, w->y0, w->fstart + n, w->pen0, w->rate0, w->acc0);
    st = gsl_odeiv2_evolve_apply(w->drv->e, w->drv->c, w->drv->s, &w->sys, &t, t_stop, &hs, w->y);
    w->cnt[MARTELLO_COUNTER_REJECTED_STEPS] += (long long)(w->drv->e->failed_steps - failed);
    if (st != GSL_SUCCESS) return gsl_failure(w, st, t, hs);
    if (t < t_stop) h = hs;   /* the last step onto a stop keeps the suggestion */
    w->cnt[MARTELLO_COUNTER_STEPS]++;
    /* the step end (a non-finite state stops the RHS here: a divergence): gap kinematics
     * and multipliers, then the earliest event inside */
    st = eval_point(w, t, w->y, w->f1, w->lam1);
    if (st != MARTELLO_OK) return fail_eval(w, st, t);
    kinematics(w, w->y, w->f1 + n, w->pen1, w->rate1, w->acc1);
    ev = locate(w, t0, t, &te);
    if (ev < 0) return ev;
    if (ev == 1) {   /* the smooth stretch ends at the event: its RHS and multipliers there */
      st = eval_point(w, te, w->y, w->f1, w->lam1);
      if (st != MARTELLO_OK) return fail_eval(w, st, te);
    }
    st = node_extrema(w, t0, ev == 1 ? te : t);
    if (st == MARTELLO_OK) st = located_peaks(w, t0, ev == 1 ? te : t, ev == 1);
    if (st != MARTELLO_OK) return st;
    if (ev == 1) {
      t = te;
      st = process_events(w, t);
      if (st != MARTELLO_OK) return st;
      /* the motion is not smooth across an event: the stepper starts afresh, and its first
       * step is no longer than the stretch just integrated (the suggestion came from the
       * motion before the event: a free flight's step is no guide to the contact after it) */
      gsl_odeiv2_driver_reset(w->drv);
      if (t > t0) h = fmin(h, t - t0);
      stuck = (t - t0 <= w->event_tol) ? stuck + 1 : 0;
      if (stuck > MAX_EVENTS_AT_ONCE)
        return fail(w, MARTELLO_ERR_STEP_UNDERFLOW, t,
                    "event-driven: events accumulate without time advancing (an unresolved "
                    "Zeno point or chattering contact)");
    }
    else if (t >= t_stop && kink) {
      gsl_odeiv2_driver_reset(w->drv);   /* across a kink of the load: start afresh */
    }
    keep_end_rates(w, ev == 0 && !(t >= t_stop && kink));
    st = commit(w, t, w->y0 + 2 * n);
    if (st != MARTELLO_OK) return st;
    if (t >= t_out) {   /* on the output grid: the observer records it */
      k = (int)(k_grid < n_out ? k_grid : n_out);
      k_out++;
    }
    st = observe(w, t, k);
    if (st != MARTELLO_OK) return st;
  }
  return MARTELLO_OK;
}

int martello_event_driven_run(martello_model *model, martello_run *run) {
  ed_t w;
  martello_settings s;
  int st, nco;
  memset(&w, 0, sizeof w);
  w.model = model;
  w.run = run;
  if (model == NULL || run == NULL) return MARTELLO_ERR_ARGUMENT;
  st = martello_run_observer(run, &w.obs);
  if (st != MARTELLO_OK) return st;
  st = martello_run_settings(run, &s);
  if (st != MARTELLO_OK) return st;
  w.kind = s.kind;
  if (w.kind != MARTELLO_INT_RKF45 && w.kind != MARTELLO_INT_RK8PD &&
      w.kind != MARTELLO_INT_MSBDF)
    return martello_observer_fail(w.obs, MARTELLO_ERR_ARGUMENT, 0.0,
                                  "event-driven: the integrator must be rkf45, rk8pd or msbdf");
  w.dt_out = s.dt;
  w.t_end = s.t_end;
  w.rtol = s.rtol;
  w.atol = s.atol;
  w.event_tol = s.event_tol;
  w.h_max = s.h_max;
  w.every = s.every;
  st = check_settings(&w);
  if (st != MARTELLO_OK) return st;
  st = martello_model_topology(model, &w.n, &w.nc, NULL, NULL, NULL, NULL, NULL, &nco);
  if (st != MARTELLO_OK) return st;
  st = ed_setup(&w);
  if (st == MARTELLO_OK) st = ed_integrate(&w);
  martello_observer_add_counts(w.obs, w.cnt);
  if (st == MARTELLO_OK) martello_observer_finish(w.obs, w.t_end);
  ed_free(&w);
  return st;
}
