/* The contact events of the SUNDIALS integrators, one copy for IDA, CVODE and ARKODE
 * (c/ode_events.h; docs/ida.md, docs/sundials-ode.md).
 *
 * Events are roots, two per contact: delta_j and its rate for open contacts and penalty
 * contacts (the rate root stops at every extremum of the gap, which gives the exact peak
 * penetration and catches a contact that opens and closes inside one step), the state's
 * multiplier for closed rigid contacts (release when it turns tensile), then one per switch
 * slot of the laws' branches. At an onset or a separation of a penalty contact, an impact
 * (Newton's law with restitution e, all contacts at zero gap at once: an impulse-level LCP), a
 * closing (e = 0, or an accumulation of impacts: the rule of docs/impulse.md §4, through
 * c/accumulation.c) or a release, the state is made consistent and the integrator restarts
 * there instead of stepping across the kink. The works, the extrema of the nodes and the
 * located peaks of every accepted step are computed on the integrator's own interpolant. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_events.h"

/* Position tolerance of a rigid contact, in units of the integrator's own: a rigid contact
 * within it of zero gap touches (it enters the impact LCP with the one whose root fired, and a
 * rebound that would not leave it has accumulated). The position error of these integrators is
 * a small multiple of their local tolerance rtol |u| + atol. */
#define POSITION_TOL_FACTOR 10.0

/* Steps per shortest harmonic period of the loads while a rigid contact is held
 * (docs/sundials-ode.md, held contacts): a multiplier excursion longer than period/HOLD_STEPS
 * contains a step end, where the root function's sign is seen; with one harmonic frequency the
 * multiplier's second derivative has at most one zero in such a step, so its rate at most one
 * extremum, and a shorter excursion is found inside the step (oe_held_release). */
#define HOLD_STEPS 16.0

/* ---- failures --------------------------------------------------------------------------- */

int oe_fail_memory(ode_events *E, const char *what, double bytes) {
  char of[192], line[480];
  snprintf(of, sizeof of, "%s for a scene of %d nodes and %d contacts", what, E->n, E->nc);
  martello_memory_message(of, bytes, NULL, line, (int)sizeof line);
  return martello_observer_fail(E->obs, MARTELLO_ERR_MEMORY, E->t_now, line);
}

int oe_fail(ode_events *E, int code, const char *fmt, ...) {
  char buf[480], what[96];
  va_list ap;
  if (code == MARTELLO_ERR_MEMORY) {
    snprintf(what, sizeof what, "the work arrays of the %s LCP solver", E->name);
    return oe_fail_memory(E, what, -1.0);
  }
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return martello_observer_fail(E->obs, code, E->t_now, buf);
}

void *oe_take(size_t count, size_t size, double *failed) {
  void *p = calloc(count > 0 ? count : 1, size);
  if (!p && *failed == 0.0) *failed = (double)(count > 0 ? count : 1) * (double)size;
  return p;
}

/* ---- kinematics ------------------------------------------------------------------------- */

/* delta = G_j u - gap, contact j's row (u_a - u_b - gap for a node pair), in the kernels'
 * order of operations (fortran/element_rows.f90). */
double oe_pen(const ode_events *E, int j, const double *u) {
  return martello_rows_dot(&E->con, j, u) - E->gap[j];
}

double oe_rate(const ode_events *E, int j, const double *v) {
  return martello_rows_dot(&E->con, j, v);
}

void oe_gather(const ode_events *E, const double *y, double *u, double *v) {
  for (int i = 0; i < E->n; i++) {
    u[i] = y[E->iu[i]];
    v[i] = y[E->iv[i]];
  }
}

/* x <- B lambda over the closed rigid contacts (x has length n). */
void oe_apply_B(const ode_events *E, const double *lam, double *x) {
  memset(x, 0, sizeof(double) * (size_t)E->n);
  for (int r = 0; r < E->nr; r++) {
    if (!E->closed[r] || lam[r] == 0.0) continue;
    martello_rows_axpy(&E->con, E->rig_con[r], lam[r], x);
  }
}

double oe_position_tol(const ode_events *E, int j, const double *u) {
  double s = fmax(fabs(E->gap[j]), martello_rows_max(&E->con, j, u));
  return POSITION_TOL_FACTOR * (E->rtol * s + E->atol);
}

static double speed_tol(const ode_events *E, const double *v) {
  double vm = 0.0;
  for (int i = 0; i < E->n; i++) vm = fmax(vm, fabs(v[i]));
  return 64.0 * DBL_EPSILON * vm + DBL_MIN;
}

/* The kernels decide a penalty law's regime by the sign of delta, so a restart exactly at
 * delta = 0 would not know on which side it is: contact j moved strictly to side sgn by the
 * smallest shift of its row's first free node. */
void oe_nudge(ode_events *E, int j, int sgn, double *u) {
  int node = -1;
  double c = 0.0;
  for (int k = E->con.first[j]; k < E->con.first[j + 1] && node < 0; k++)
    if (!E->fixed[E->con.node[k]] && E->con.coef[k] != 0.0) {
      node = E->con.node[k];
      c = E->con.coef[k];
    }
  if (node < 0) return;
  double eta = 4.0 * DBL_EPSILON * (fabs(E->gap[j]) + martello_rows_abs(&E->con, j, u)) + DBL_MIN;
  for (int k = 0; k < 80; k++) {
    double d = oe_pen(E, j, u);
    if (sgn * d > 0.0) return;
    u[node] += sgn * (fabs(d) + eta) / c;
    eta *= 2.0;
  }
}

/* The value of switch slot s on (u, v): g > 0 once its branch is left (fortran/switching.f90). */
static double switch_value(const ode_events *E, int s, const double *u, const double *v) {
  const int e = E->sw_el[s];
  const double du = e >= 0 ? martello_rows_dot(&E->elem, e, u) : 0.0;
  const double dv = e >= 0 ? martello_rows_dot(&E->elem, e, v) : 0.0;
  return E->sw_al[s] * du + E->sw_be[s] * dv + E->sw_ga[s];
}

/* The root finder reports a switch where g has changed sign or is exactly 0 (an exact zero is
 * a root), and the located state may sit on the surface within its rounding. The commit leaves
 * a branch only past its surface (g > 0 as the kernels compute it again from the committed
 * state, fortran/switching.f90): a restart on the surface would keep the branch, and the root,
 * 0 there, is not reported again, so the branch would change at the next commit, a whole step
 * late (docs/sundials-ode.md, events and restarts). Switch s, reported rising, is moved past its
 * surface beyond that rounding (16 eps of its terms, as c/event_driven.c's switch_rounding) by
 * the smallest shift of one free node of its element: its u where g depends on u, else its v.
 * Reported falling (dir = -1: back towards the branch held), it is moved to the branch's side
 * beyond the rounding: where the committed branch's surface passes through the state (a
 * bilinear spring unloading at its yield point, g = 0 falling) the root would otherwise be met
 * again at once after every restart. */
static void past_switch(ode_events *E, int s, double *u, double *v, double dir) {
  const int e = E->sw_el[s];
  const double al = E->sw_al[s], be = E->sw_be[s];
  if (e < 0 || (al == 0.0 && be == 0.0)) return;
  double *x = al != 0.0 ? u : v, a = al != 0.0 ? al : be, c = 0.0;
  int node = -1;
  for (int k = E->elem.first[e]; k < E->elem.first[e + 1] && node < 0; k++)
    if (!E->fixed[E->elem.node[k]] && E->elem.coef[k] != 0.0) {
      node = E->elem.node[k];
      c = E->elem.coef[k];
    }
  if (node < 0) return;
  for (int k = 0; k < 80; k++) {
    const double rounding = 16.0 * DBL_EPSILON *
                            (fabs(al) * martello_rows_abs(&E->elem, e, u) +
                             fabs(be) * martello_rows_abs(&E->elem, e, v) + fabs(E->sw_ga[s])) + DBL_MIN;
    const double g = dir * switch_value(E, s, u, v);
    if (g > rounding) return;
    x[node] += dir * ldexp(rounding - g + rounding, k) / (a * c);
  }
}

/* ---- the impulse problem of the rigid contacts -------------------------------------------- */

/* M^-1 B_r^T of every rigid contact, once (the mass matrix does not change). */
static int impulse_columns(ode_events *E) {
  if (E->cols_ready) return MARTELLO_OK;
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r], st;
    double *c = E->cols + (size_t)r * (size_t)E->n;
    memset(c, 0, sizeof(double) * (size_t)E->n);
    martello_rows_axpy(&E->con, j, -1.0, c);       /* B_j^T = -G_j^T */
    if ((st = martello_eval_solve_mass(E->ev, c)) != MARTELLO_OK) return st;
  }
  E->cols_ready = 1;
  return MARTELLO_OK;
}

/* The rigid contacts aset[0..m) as the impulse door's list (contact indices) into dc. */
static void door_list(ode_events *E, int m) {
  for (int k = 0; k < m; k++) E->dc[k] = E->rig_con[E->aset[k]];
}

/* The impulse door's topology arguments (c/martello_internal.h): sides, columns in cols. */
#define TOPOLOGY(E) &(E)->con, (E)->rig, (E)->cols

static int closed_set(ode_events *E) {
  int m = 0;
  for (int r = 0; r < E->nr; r++)
    if (E->closed[r]) E->aset[m++] = r;
  return m;
}

/* From the state itself: an index-2 multiplier integrated with the state (IDA's P, out of its
 * error test) is not accurate between the steps' ends: while a contact holds a node still the
 * steps grow to the output interval and the root of IDA's interpolated P fell up to 8e-3 s
 * from the release (P9 at rtol 1e-11), at a time that moved with the output interval. */
int oe_closed_multipliers(ode_events *E, double t, const double *u, const double *v) {
  int st = martello_eval_acceleration(E->ev, t, u, v, E->ar);
  if (st == MARTELLO_OK) st = oe_constrain(E, E->ar);
  for (int k = 0; k < E->mc; k++) E->lr[E->lc[k]] = E->x[k];
  return st;
}

int oe_constrain(ode_events *E, double *a) {
  if (E->mc == 0) return MARTELLO_OK;
  return martello_impulse_project(E->n, E->mc, E->dlc, TOPOLOGY(E), E->Wc, NULL, a, E->x);
}

/* The release roots from the restart on: the closed set, W_H factored, and each contact's
 * tension bar, the rounding of the forces at its nodes (as on the event-driven integrator). */
static int closed_set_roots(ode_events *E) {
  E->mc = 0;
  for (int r = 0; r < E->nr; r++)
    if (E->closed[r]) {
      int j = E->rig_con[r];
      double fs = fabs(E->lam[r]);
      for (int k = E->con.first[j]; k < E->con.first[j + 1]; k++)
        fs += fabs(E->con.coef[k]) * E->mass[E->con.node[k]] * fabs(E->a[E->con.node[k]]);
      E->lamtol[r] = 1e3 * DBL_EPSILON * fs;
      E->lc[E->mc] = r;
      E->dlc[E->mc++] = j;
    }
  if (E->mc == 0) return MARTELLO_OK;
  return martello_impulse_factor(E->n, E->mc, E->dlc, TOPOLOGY(E), E->Wc);
}

/* Zero the rates of the closed set (for an accumulation this removes the rest of the
 * bounces: their energy goes to E_IMPACT), then put it on delta = 0 (B u = -gap) by the
 * mass-weighted projection: at every restart, so that the integrator starts on the
 * constraints. */
static int project_closed(ode_events *E, double t, double *u, double *v) {
  int st, m = closed_set(E);
  if (m == 0) return MARTELLO_OK;
  door_list(E, m);
  if ((st = martello_impulse_factor(E->n, m, E->dc, TOPOLOGY(E), E->S)) != MARTELLO_OK)
    return oe_fail(E, MARTELLO_ERR_SINGULAR, "%s: redundant closed contacts at t = %.9e s (B^T M^-1 B singular)", E->name, t);
  for (int k = 0; k < m; k++) E->q[k] = -E->gap[E->rig_con[E->aset[k]]];
  st = martello_impulse_project(E->n, m, E->dc, TOPOLOGY(E), E->S, NULL, v, E->rhs);
  if (st == MARTELLO_OK)
    st = martello_impulse_project(E->n, m, E->dc, TOPOLOGY(E), E->S, E->q, u, E->rhs);
  if (st != MARTELLO_OK) return oe_fail(E, st, "%s: the constraint projection failed at t = %.9e s", E->name, t);
  return MARTELLO_OK;
}

/* Newton's impact law on the rigid contacts that touch (closed, flagged ACT_IMPACT, or open
 * at zero gap within the position tolerance), all at once (martello_impulse_newton:
 * simultaneous impacts in a chain), restitution e (0 for a closed contact). E->hit and
 * E->w_in say which contacts took an impulse and their approach speed. Then the closing
 * rule (the accumulation policy) and, for the closed set, zero rates and positions. */
static int rigid_impacts(ode_events *E, double t, double *u, double *v) {
  int st, m = 0, piv;
  if ((st = impulse_columns(E)) != MARTELLO_OK) return oe_fail(E, st, "%s: singular mass at an impact", E->name);
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r];
    E->hit[r] = 0;
    /* a contact released here leaves at rest: it takes no impulse (its rounding-level rate
     * made a spurious impact at 1e-35 m/s on P9 when the release fell on an output time) */
    E->cand[r] = E->closed[r] || E->act[j] == ACT_IMPACT ||
                 (E->act[j] != ACT_RELEASE && oe_pen(E, j, u) >= -oe_position_tol(E, j, u));
    if (E->cand[r]) E->aset[m++] = r;
  }
  if (m > 0) {
    door_list(E, m);
    for (int k = 0; k < m; k++) {
      int r = E->aset[k], j = E->rig_con[r];
      E->w0[k] = oe_rate(E, j, v);
      E->q[k] = E->closed[r] ? 0.0 : (E->rest[j] >= 0.0 ? E->rest[j] : 0.0);
    }
    st = martello_impulse_newton(E->n, m, E->dc, TOPOLOGY(E), E->q, v, E->rhs, &piv);
    if (st != MARTELLO_OK)
      return oe_fail(E, st, "%s: the impact LCP of %d contacts failed at t = %.9e s (%s)", E->name, m, t,
                     st == MARTELLO_ERR_SINGULAR ? "redundant contacts" : "pivot limit");
    for (int k = 0; k < m; k++) {
      int r = E->aset[k], j = E->rig_con[r];
      if (E->rhs[k] > 0.0 && !E->closed[r]) {
        E->hit[r] = 1;
        E->w_in[j] = E->w0[k];
        E->w_out[j] = oe_rate(E, j, v);
        if (E->act[j] != ACT_IMPACT) E->events++;
      }
    }
    /* a closed contact that the impact sets apart (p = 0, separating) opens */
    double vtol = speed_tol(E, v);
    for (int r = 0; r < E->nr; r++)
      if (E->closed[r] && oe_rate(E, E->rig_con[r], v) < -vtol) {
        E->closed[r] = 0;
        E->opened[r] = 1;
      }
  }
  /* closing: the accumulation rule (docs/impulse.md §4) with the integrator's resolutions
   * (event_tol, the position tolerance of the contact and the like one of its rate), and the
   * normal acceleration a_n that presses each contact that took an impulse with the contacts
   * already closed enforced (their forces from the persistent-contact rule): aset = [closed
   * set, candidates]. The phase of a contact closed here starts at its accumulation point. */
  int mc = closed_set(E), ma = mc;
  for (int r = 0; r < E->nr; r++)
    if (!E->closed[r] && (E->hit[r] || E->act[E->rig_con[r]] == ACT_IMPACT)) E->aset[ma++] = r;
  if (ma > mc) {
    st = martello_eval_acceleration(E->ev, t, u, v, E->a);
    if (st != MARTELLO_OK) return oe_fail(E, st, "%s: acceleration failed at t = %.9e s", E->name, t);
    door_list(E, ma);
    st = martello_impulse_delassus(E->n, ma, E->dc, TOPOLOGY(E), E->S);
    if (st == MARTELLO_OK && mc > 0)
      st = martello_impulse_contact_forces(E->n, mc, E->dc, TOPOLOGY(E), E->a, E->w0,
                                           E->cand, &piv);
    if (st != MARTELLO_OK)
      return oe_fail(E, st, "%s: the contact forces of the closed contacts failed at t = %.9e s", E->name, t);
  }
  for (int k = mc; k < ma; k++) {
    int r = E->aset[k], j = E->rig_con[r];
    double an = oe_rate(E, j, E->a), rebound = fmax(-oe_rate(E, j, v), 0.0);
    double e = E->rest[j] >= 0.0 ? E->rest[j] : 0.0;
    double v_res = POSITION_TOL_FACTOR *
                   (E->rtol * martello_rows_abs(&E->con, j, v) + E->atol);
    double da = 0.0;
    for (int l = 0; l < mc; l++) an -= E->S[k + ma * l] * E->w0[l];
    if (rebound > 0.0 && an > 0.0) {
      /* the change of a_n over the next flight tau = 2 s/a_n, at the end of a tangent step of
       * length tau (the closed contacts' forces held) */
      const double tau = 2.0 * rebound / an;
      for (int i = 0; i < E->n; i++) {
        E->uq[i] = u[i] + tau * v[i];
        E->vq[i] = v[i] + tau * E->a[i];
      }
      st = martello_eval_acceleration(E->ev, t + tau, E->uq, E->vq, E->x);
      if (st != MARTELLO_OK) return oe_fail(E, st, "%s: acceleration failed at t = %.9e s", E->name, t + tau);
      da = oe_rate(E, j, E->x) - oe_rate(E, j, E->a);
    }
    /* tentative: rigid_multipliers opens it again if its multiplier is not compressive. A
     * contact that nothing presses (a_n <= 0) stays open, as on the event-driven integrator:
     * bodies that move on together after a plastic impact are not in a persistent contact */
    if (an > 0.0 && martello_accumulation_decide(&E->acc, j, e, rebound, an, da, t,
                                                 E->event_tol, oe_position_tol(E, j, u), v_res,
                                                 E->restarts))
      E->closed[r] = 1;
  }
  return project_closed(E, t, u, v);
}

/* Multipliers of the closed set: the persistent-contact rule (martello_impulse_contact_forces
 * on the free accelerations); a contact that the solution opens (lambda = 0, opening
 * acceleration) opens. Leaves a_free in E->a and the multipliers in E->lam. */
static int rigid_multipliers(ode_events *E, double t, double *u, double *v) {
  int st = martello_eval_acceleration(E->ev, t, u, v, E->a), piv;
  if (st != MARTELLO_OK) return oe_fail(E, st, "%s: acceleration failed at t = %.9e s", E->name, t);
  for (int r = 0; r < E->nr; r++) E->lam[r] = 0.0;
  int m = closed_set(E);
  if (m == 0) return MARTELLO_OK;
  if ((st = impulse_columns(E)) != MARTELLO_OK) return oe_fail(E, st, "%s: singular mass", E->name);
  door_list(E, m);
  st = martello_impulse_contact_forces(E->n, m, E->dc, TOPOLOGY(E), E->a, E->rhs,
                                       E->cand, &piv);
  if (st != MARTELLO_OK)
    return oe_fail(E, st, "%s: the contact forces of %d closed contacts failed at t = %.9e s (%s)", E->name, m, t,
                   st == MARTELLO_ERR_SINGULAR ? "redundant closed contacts" : "pivot limit");
  for (int k = 0; k < m; k++) {
    int r = E->aset[k];
    if (E->cand[k]) {
      E->lam[r] = E->rhs[k];
    } else {
      E->closed[r] = 0;
      E->opened[r] = 1;
    }
  }
  return MARTELLO_OK;
}

/* ---- what the observer is handed ---------------------------------------------------------- */

/* An output row's commit: the links' states and the onset speeds located so far, which the
 * step's own commit still takes (they are not consumed here). */
static int commit_row(ode_events *E, const double *u, const double *v) {
  int st = martello_eval_commit(E->ev, u, v);
  for (int k = 0; k < E->nvin && st == MARTELLO_OK; k++) {
    int j = E->vin_j[k];
    if (E->vin[j] > 0.0) st = martello_eval_set_onset_speed(E->ev, j, E->vin[j]);
  }
  return st;
}

int oe_commit(ode_events *E, const double *u, const double *v) {
  int st = martello_eval_commit(E->ev, u, v);
  if (st == MARTELLO_OK && E->nsw > 0)
    st = martello_eval_switches(E->ev, E->sw_el, E->sw_al, E->sw_be, E->sw_ga);
  /* the onset speeds located inside the step replace the commit's interpolated ones */
  for (int k = 0; k < E->nvin && st == MARTELLO_OK; k++) {
    int j = E->vin_j[k];
    if (E->vin[j] > 0.0) st = martello_eval_set_onset_speed(E->ev, j, E->vin[j]);
    E->vin[j] = 0.0;
  }
  E->nvin = 0;
  E->nev = 0;
  return st;
}

int oe_hand_work(ode_events *E) {
  int st = martello_observer_work(E->obs, E->dw_ext, E->dw_int, E->dw_links, E->dw_contact,
                                  E->e_impact);
  E->dw_ext = E->dw_int = E->dw_links = E->dw_contact = E->e_impact = 0.0;
  return st == MARTELLO_OK ? st : oe_fail(E, st, "%s: could not hand the works to the observer", E->name);
}

/* Work of the external and internal forces (and of the links other than dampers and of the
 * penalty contacts) over [t0, t1] on the step's interpolant, 3-point Gauss-Legendre (order
 * 6), with the link states committed at t0 (as the integrator's residuals saw them). */
static int work_quadrature(ode_events *E, double t0, double t1) {
  static const double xg[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  if (!(t1 > t0)) return MARTELLO_OK;
  double h = t1 - t0, we = 0.0, wi = 0.0, wl = 0.0, wc = 0.0, power[5];
  for (int k = 0; k < 3; k++) {
    double tk = t0 + 0.5 * h * (1.0 + xg[k]);
    int st = E->dky(E->ctx, tk, 0, E->ytmp);
    if (st != MARTELLO_OK) return st;
    oe_gather(E, N_VGetArrayPointer(E->ytmp), E->uq, E->vq);
    st = martello_eval_forces(E->ev, tk, E->uq, E->vq, E->fint, E->fext);
    if (st == MARTELLO_OK) st = martello_eval_power(E->ev, power);
    if (st != MARTELLO_OK) return oe_fail(E, st, "%s: force evaluation failed at t = %.9e s", E->name, tk);
    we += wg[k] * power[0];
    wi += wg[k] * power[1];
    wl += wg[k] * power[3];
    wc += wg[k] * power[4];
  }
  E->dw_ext += h * we;
  E->dw_int += h * wi;
  E->dw_links += h * wl;
  E->dw_contact += h * wc;
  return MARTELLO_OK;
}

/* The extrema of the node displacements on [t0, t1], inside the last step: a node whose
 * velocity changes sign against E->v_last gets the root of v located by bisection on the
 * interpolant (of the method's order: the error of the step) and u there (docs/run-layer.md,
 * located extrema). */
static int taylor(ode_events *E);
static double tay(const double *c, int n, int i, int q, double s, int deriv);

static int node_extrema(ode_events *E, double t0, double t1, const double *y1) {
  for (int i = 0; i < E->n; i++) {
    const double v0 = E->v_last[i], v1 = y1[E->iv[i]];
    int is_max, st;
    if (E->fixed[i]) continue;
    /* a turn inside the velocity's own tolerance is not resolved: its sign is the error's (as
     * on c/event_driven.c: u ~ 1e-150 m ahead of a wave front turned back and forth with the
     * steps; docs/results.md, u_peak) */
    if (!(fmax(fabs(v0), fabs(v1)) > E->atol)) continue;
    if (v0 > 0.0 && v1 <= 0.0) is_max = 1;
    else if (v0 < 0.0 && v1 >= 0.0) is_max = 0;
    else continue;
    double lo = t0, hi = t1, u = y1[E->iu[i]];
    if (E->degree) {
      /* on the node's own Taylor coefficients: O(degree) an iteration, not O(n) */
      if ((st = taylor(E)) != MARTELLO_OK) return st;
      for (int it = 0; it < 200 && hi - lo > fmax(E->event_tol, 4.0 * DBL_EPSILON * fabs(hi)); it++) {
        const double tm = 0.5 * (lo + hi);
        if ((tay(E->tay_v, E->n, i, E->tay_q, tm - E->t_step, 0) > 0.0) == (v0 > 0.0)) lo = tm; else hi = tm;
      }
      if (hi < t1) u = tay(E->tay_u, E->n, i, E->tay_q, hi - E->t_step, 0);
    } else {
      for (int it = 0; it < 200 && hi - lo > fmax(E->event_tol, 4.0 * DBL_EPSILON * fabs(hi)); it++) {
        const double tm = 0.5 * (lo + hi);
        if ((st = E->dky(E->ctx, tm, 0, E->ytmp)) != MARTELLO_OK) return st;
        if ((N_VGetArrayPointer(E->ytmp)[E->iv[i]] > 0.0) == (v0 > 0.0)) lo = tm; else hi = tm;
      }
      if (hi < t1) {
        if ((st = E->dky(E->ctx, hi, 0, E->ytmp)) != MARTELLO_OK) return st;
        u = N_VGetArrayPointer(E->ytmp)[E->iu[i]];
      }
    }
    st = martello_observer_extremum(E->obs, oe_gnode(E, i), hi, u, is_max);
    if (st != MARTELLO_OK) return oe_fail(E, st, "%s: martello_observer_extremum failed", E->name);
  }
  return MARTELLO_OK;
}

/* u, v, a (E->ua, va, aa) of the nodes at t on the interpolant (y and y': a is the v rows of
 * y'), and the rates of the peak quantities there: elements into e (packed), node jerks into
 * jerk. */
static int interpolated_rates(ode_events *E, double t, double *e, double *jerk) {
  int st = E->dky(E->ctx, t, 0, E->ytd);
  if (st != MARTELLO_OK) return st;
  oe_gather(E, N_VGetArrayPointer(E->ytd), E->ua, E->va);
  if ((st = E->dky(E->ctx, t, 1, E->ytd)) != MARTELLO_OK) return st;
  for (int i = 0; i < E->n; i++) E->aa[i] = N_VGetArrayPointer(E->ytd)[E->iv[i]];
  st = martello_peak_rates(E->ev, t, E->ua, E->va, E->aa, E->nc, E->nl, e, jerk);
  return st == MARTELLO_OK ? st : oe_fail(E, st, "%s: the rates of the peaks failed at t = %.9e s", E->name, t);
}

/* The probe of c/located_peaks.c on the interpolant of the last step (of the method's order:
 * its own solution between the steps' ends). */
static int peak_probe(void *ctx, double t, int kind, int j, double *q, double *r) {
  ode_events *E = ctx;
  int st = interpolated_rates(E, t, E->elc, E->jk);
  if (st != MARTELLO_OK) return st;
  martello_peak_pick(kind, j, E->nc, E->nl, E->va, E->aa, E->jk, E->elc, q, r);
  return MARTELLO_OK;
}

/* Fixed nodes, rigid contacts and penalty contacts out of a phase have no peak here. */
static int peak_skip(void *ctx, int kind, int j) {
  ode_events *E = ctx;
  if (kind == MARTELLO_PEAK_V || kind == MARTELLO_PEAK_A) return E->fixed[j];
  if (kind == MARTELLO_PEAK_PEN || kind == MARTELLO_PEAK_FORCE)
    return E->rig[j] >= 0 || !martello_observer_in_phase(E->obs, oe_gcon(E, j));
  return 0;
}

/* The peaks inside [t0, t1] of the last step, on its interpolant (docs/run-layer.md, located
 * peaks): every quantity's value and rate at both ends (the start's kept from the last step's
 * end when the integrator went on: E->start_rates), then c/located_peaks.c. */
static int located_peaks(ode_events *E, double t0, double t1, int at_event) {
  const size_t nb = sizeof(double) * (size_t)E->n;
  martello_peak_ends e;
  int st;
  if (!(t1 > t0)) return MARTELLO_OK;
  if (!E->start_rates) {
    if ((st = interpolated_rates(E, t0, E->el0, E->pj0)) != MARTELLO_OK) return st;
    memcpy(E->pv0, E->va, nb);
    memcpy(E->pa0, E->aa, nb);
  }
  if ((st = interpolated_rates(E, t1, E->el1, E->pj1)) != MARTELLO_OK) return st;
  memcpy(E->pv1, E->va, nb);
  memcpy(E->pa1, E->aa, nb);
  memset(&e, 0, sizeof e);
  martello_peak_ends_set(&e, 0, E->n, E->nc, E->nl, E->pv0, E->pa0, E->pj0, E->el0);
  martello_peak_ends_set(&e, 1, E->n, E->nc, E->nl, E->pv1, E->pa1, E->pj1, E->el1);
  e.skip = peak_skip;
  e.global[MARTELLO_PEAK_V] = e.global[MARTELLO_PEAK_A] = E->g_node;
  e.global[MARTELLO_PEAK_PEN] = e.global[MARTELLO_PEAK_FORCE] = E->g_con;
  e.global[MARTELLO_PEAK_LINK_FORCE] = e.global[MARTELLO_PEAK_LINK_DU] = E->g_link;
  if (at_event && (st = martello_peak_fold_end(E->obs, &e, E)) != MARTELLO_OK) return st;
  return martello_locate_peaks(E->obs, &e, t0, t1, E->rtol, E->event_tol, peak_probe, E);
}

int oe_stretch(ode_events *E, double t0, double t1, const double *y1, int at_event) {
  int st = work_quadrature(E, t0, t1);
  if (st == MARTELLO_OK) st = node_extrema(E, t0, t1, y1);
  if (st == MARTELLO_OK) st = located_peaks(E, t0, t1, at_event);
  return st;
}

void oe_keep_end_rates(ode_events *E, int unchanged) {
  double *tmp;
  E->start_rates = unchanged;
  if (!unchanged) return;
  tmp = E->el0; E->el0 = E->el1; E->el1 = tmp;
  tmp = E->pj0; E->pj0 = E->pj1; E->pj1 = tmp;
  tmp = E->pv0; E->pv0 = E->pv1; E->pv1 = tmp;
  tmp = E->pa0; E->pa0 = E->pa1; E->pa1 = tmp;
}

/* Two stops closer than this many units of rounding of their time are one (oe_next_stop). */
#define STOP_ROUNDING (16.0 * DBL_EPSILON)

double oe_next_stop(ode_events *E, double t, double t_to, int *kink) {
  double tb = DBL_MAX;
  if (martello_eval_next_breakpoint(E->ev, t, &tb) != MARTELLO_OK) tb = DBL_MAX;
  /* a kink within rounding of t is the one just passed (two loads' kinks an ulp apart: a
   * record's sample and a window's end), and one within rounding of t_to is t_to (a record
   * sampled at 0.01 s, outputs every 0.015 s: the times differ by an ulp or two): one stop,
   * never a step of an ulp (as c/event_driven.c) */
  if (tb - t <= STOP_ROUNDING * fabs(t) && martello_eval_next_breakpoint(E->ev, tb, &tb) != MARTELLO_OK)
    tb = DBL_MAX;
  *kink = tb <= t_to + STOP_ROUNDING * fabs(t_to);
  return tb < t_to - STOP_ROUNDING * fabs(t_to) ? tb : t_to;
}

double oe_max_step(const ode_events *E) {
  if (E->h_hold > 0.0)
    for (int r = 0; r < E->nr; r++)
      if (E->closed[r]) return E->h_max > 0.0 ? fmin(E->h_max, E->h_hold) : E->h_hold;
  return E->h_max;
}

double oe_output_time(const ode_events *E, int k) {
  double t = fmin((double)(k * E->every) * E->dt, E->t_end);   /* t = k dt, as on GSL */
  return E->t_end - t <= 1e-9 * E->out_dt ? E->t_end : t;
}

int oe_rows_inside(ode_events *E, double *t_last, double t1, int *k_out, double *t_out) {
  int st;
  while (*t_out < t1) {
    const double t = *t_out;
    if ((st = E->dky(E->ctx, t, 0, E->yrow)) != MARTELLO_OK) return st;
    const double *y = N_VGetArrayPointer(E->yrow);
    if ((st = oe_inner_events(E, *t_last, t, y)) != MARTELLO_OK) return st;
    if ((st = oe_stretch(E, *t_last, t, y, 0)) != MARTELLO_OK) return st;
    oe_keep_end_rates(E, 1);
    /* The row is committed for its own values (link states, onset speeds located before it),
     * then the step's element states come back: a commit kept here moved the later steps
     * with the output interval (ARKODE on P7's chain of 10: 1546 / 1547 / 1543 steps at
     * output.every 1 / 7 / 50; 1544 at each with the states restored). */
    oe_gather(E, y, E->u, E->v);
    if ((st = martello_eval_save(E->ev)) != MARTELLO_OK ||
        (st = commit_row(E, E->u, E->v)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: commit failed", E->name);
    if ((st = oe_hand_work(E)) != MARTELLO_OK) return st;
    if ((st = E->sample(E->ctx, t, y, *k_out * E->every)) != MARTELLO_OK) return st;
    if ((st = martello_eval_restore(E->ev)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: restoring the step's states failed", E->name);
    oe_accepted(E, y);
    *t_last = t;
    *t_out = oe_output_time(E, ++*k_out);
  }
  return MARTELLO_OK;
}

int oe_add_counts(ode_events *E, const long c[9]) {
  long long inc[MARTELLO_NCOUNTERS] = {0};
  for (int k = 0; k < 9; k++) {
    if (k == MARTELLO_COUNTER_EVENTS || k == MARTELLO_COUNTER_CONTACT_CHATTER_RESOLUTIONS) continue;
    inc[k] = c[k] >= E->cnt_last[k] ? c[k] - E->cnt_last[k] : c[k];
    E->cnt_last[k] = c[k];
  }
  inc[MARTELLO_COUNTER_EVENTS] = E->events;
  E->events = 0;
  return martello_observer_add_counts(E->obs, inc);
}

/* ---- roots and events ----------------------------------------------------------------------- */

int oe_nroots(const ode_events *E) { return 2 * E->nc + E->nsw; }

int oe_roots(ode_events *E, double t, const double *u, const double *v, double *g) {
  if (E->mc > 0 && oe_closed_multipliers(E, t, u, v) != MARTELLO_OK) return -1;
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    if (r >= 0 && E->closed[r]) {
      g[2 * j] = E->lr[r] + E->lamtol[r];
      g[2 * j + 1] = 1.0;
    } else if (E->smooth && E->cont[j]) {
      g[2 * j] = g[2 * j + 1] = 1.0;   /* located inside the steps, never a root */
    } else {
      g[2 * j] = oe_pen(E, j, u);
      g[2 * j + 1] = oe_rate(E, j, v);
    }
  }
  for (int s = 0; s < E->nsw; s++) g[2 * E->nc + s] = switch_value(E, s, u, v);
  return 0;
}

/* Bisection on the interpolant of the last step for the crossing of delta_j between tl and tr;
 * returns a time on the tl side within event_tol. */
static int locate(ode_events *E, int j, double tl, double tr, double *t_cross) {
  int st = E->dky(E->ctx, tl, 0, E->ytmp);
  if (st != MARTELLO_OK) return st;
  oe_gather(E, N_VGetArrayPointer(E->ytmp), E->uq, E->vq);
  int left_positive = oe_pen(E, j, E->uq) > 0.0;
  for (int it = 0; it < 200 && tr - tl > fmax(E->event_tol, 4.0 * DBL_EPSILON * fabs(tr)); it++) {
    double tm = 0.5 * (tl + tr);
    if ((st = E->dky(E->ctx, tm, 0, E->ytmp)) != MARTELLO_OK) return st;
    oe_gather(E, N_VGetArrayPointer(E->ytmp), E->uq, E->vq);
    if ((oe_pen(E, j, E->uq) > 0.0) == left_positive) tl = tm; else tr = tm;
  }
  *t_cross = tl;
  return MARTELLO_OK;
}

int oe_classify_roots(ode_events *E, double t_last, double tret, const double *y,
                      const int *found, double *t_r) {
  oe_gather(E, y, E->u, E->v);
  double best = tret;
  int jbest = -1, kbest = ACT_NONE;
  /* extrema of gaps: peaks, and contacts that opened and closed inside one step */
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    if (!found[2 * j + 1] || found[2 * j]) continue;
    if (r >= 0 && E->closed[r]) continue;
    double d = oe_pen(E, j, E->u);
    int want = ACT_NONE, touching = martello_observer_in_phase(E->obs, oe_gcon(E, j));
    if (r < 0) {
      /* touching with d > 0: the deepest point, sampled there as an accepted state */
      if (!touching && d > 0.0) want = ACT_ONSET;
      else if (touching && d < 0.0) want = ACT_SEPARATION;
    } else if (d > 0.0) {
      want = ACT_IMPACT;
    }
    if (want == ACT_NONE) continue;
    double tc;
    int st = locate(E, j, t_last, tret, &tc);
    if (st != MARTELLO_OK) return st;
    if (jbest < 0 || tc < best) {
      best = tc;
      jbest = j;
      kbest = want;
    }
  }
  if (jbest >= 0) {
    E->act[jbest] = kbest;
    *t_r = best;
    return 1;
  }
  int any = 0;
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j], dir = found[2 * j], touching = martello_observer_in_phase(E->obs, oe_gcon(E, j));
    if (dir == 0) continue;
    if (r < 0) {
      if (dir > 0 && !touching) E->act[j] = ACT_ONSET;
      else if (dir < 0 && touching) E->act[j] = ACT_SEPARATION;
    } else if (!E->closed[r]) {
      if (dir > 0) E->act[j] = ACT_IMPACT;
    } else if (dir < 0) {
      E->act[j] = ACT_RELEASE;
    }
    any |= E->act[j] != ACT_NONE;
  }
  /* a branch of a law left: the restart at the root commits the next one */
  for (int s = 0; s < E->nsw; s++)
    if (found[2 * E->nc + s]) {
      E->sw_hit[s] = found[2 * E->nc + s];
      any = 1;
    }
  *t_r = tret;
  return any;
}

/* A root function exactly 0 at the return stays 0 when two nodes move identically (identical
 * neighbours never touch, docs/problems.md P7; rigid clusters of a chain): the integrator
 * would stop on it again at once and fail with "root found at and very near t". */
int oe_root_stays_zero(ode_events *E, const double *y, const int *found) {
  oe_gather(E, y, E->uq, E->vq);
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    if (r >= 0 && E->closed[r]) continue;
    if ((found[2 * j] && oe_pen(E, j, E->uq) == 0.0) ||
        (found[2 * j + 1] && oe_rate(E, j, E->vq) == 0.0))
      return 1;
  }
  return 0;
}

/* An analytic event time that coincides with a stop time lands exactly on delta = 0, where the
 * root finder reports no sign change, and the kink would then sit at the start of every
 * following step. */
int oe_boundary_events(ode_events *E, double t_last, double tret, const double *y,
                       double h_last, double *t_r) {
  oe_gather(E, y, E->u, E->v);
  double best = tret;
  int jbest = -1, kbest = ACT_NONE;
  double vmax = 0.0;
  for (int i = 0; i < E->n; i++) vmax = fmax(vmax, fabs(E->v[i]));
  double wtol = 10.0 * (E->rtol * vmax + E->atol);
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j], want = ACT_NONE, touching = martello_observer_in_phase(E->obs, oe_gcon(E, j));
    if ((r >= 0 && E->closed[r]) || (E->smooth && E->cont[j])) continue;
    double d = oe_pen(E, j, E->u), w = oe_rate(E, j, E->v);
    /* on the surface within round-off of the gap, or of the time */
    double on = 64.0 * DBL_EPSILON *
                (martello_rows_abs(&E->con, j, E->u) + fabs(E->gap[j]) +
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
      int st = locate(E, j, t_last, tret, &tc);
      if (st != MARTELLO_OK) return st;
    }
    if (jbest < 0 || tc < best) {
      best = tc;
      jbest = j;
      kbest = want;
    }
  }
  if (jbest < 0) return 0;
  E->act[jbest] = kbest;
  *t_r = best;
  return 1;
}

int oe_prepare_restart(ode_events *E, double t, double *u, double *v) {
  int st, any_rigid = 0;
  double ke0 = 0.0, ke1 = 0.0, dummy;
  for (int s = 0; s < E->nsw; s++) {
    if (E->sw_hit[s] != 0) past_switch(E, s, u, v, E->sw_hit[s] > 0 ? 1.0 : -1.0);
    E->sw_hit[s] = 0;
  }
  if ((st = martello_eval_energy(E->ev, u, v, &ke0, &dummy)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: energy evaluation failed", E->name);
  for (int r = 0; r < E->nr; r++) E->opened[r] = 0;
  for (int j = 0; j < E->nc; j++) {
    int r = E->rig[j];
    double w = oe_rate(E, j, v);
    switch (E->act[j]) {
    case ACT_ONSET:
      oe_nudge(E, j, +1, u);
      martello_observer_set_phase(E->obs, oe_gcon(E, j), 1, t, w);
      E->events++;
      break;
    case ACT_SEPARATION:
      oe_nudge(E, j, -1, u);
      martello_observer_set_phase(E->obs, oe_gcon(E, j), 0, t, w);
      E->events++;
      break;
    case ACT_IMPACT:
      E->w_in[j] = w;
      any_rigid = 1;
      E->events++;
      break;
    case ACT_RELEASE:
      E->closed[r] = 0;
      oe_nudge(E, j, -1, u);
      martello_accumulation_release(&E->acc, E->obs, j, t, w);
      any_rigid = 1;
      E->events++;
      break;
    default:
      break;
    }
  }
  for (int r = 0; r < E->nr; r++) {
    E->was_closed[r] = E->closed[r];
    E->hit[r] = 0;
  }
  if (any_rigid && (st = rigid_impacts(E, t, u, v)) != MARTELLO_OK) return st;
  if (!any_rigid && E->nr > 0 && (st = project_closed(E, t, u, v)) != MARTELLO_OK) return st;
  /* rebounding (not closed) contacts leave from delta < 0 so that the gap root sees the
   * next approach as a sign change */
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r];
    if ((E->hit[r] || E->act[j] == ACT_IMPACT) && !E->closed[r]) oe_nudge(E, j, -1, u);
  }
  if ((st = oe_commit(E, u, v)) != MARTELLO_OK) return oe_fail(E, st, "%s: commit failed", E->name);
  if (E->nr > 0 && (st = rigid_multipliers(E, t, u, v)) != MARTELLO_OK) return st;
  if (E->nr == 0 && (st = martello_eval_acceleration(E->ev, t, u, v, E->a)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: acceleration failed at t = %.9e s", E->name, t);
  for (int r = 0; r < E->nr; r++) {
    int j = E->rig_con[r];
    if (E->opened[r]) oe_nudge(E, j, -1, u);
    if ((E->hit[r] || E->act[j] == ACT_IMPACT) && !E->was_closed[r]) {
      /* every impulse is an impact (its rebound as Newton's law left it); a contact it closes
       * is persistent from its accumulation point (an instant later for a plastic impact or
       * one touching at rest), as on the event-driven integrator */
      if (E->hit[r]) martello_observer_add_impact(E->obs, j, t, E->w_in[j], E->w_out[j], 0.0, 0.0);
      if (E->closed[r]) martello_accumulation_hold(&E->acc, E->obs, j);
    } else if (E->opened[r] && martello_observer_in_phase(E->obs, j)) {
      martello_accumulation_release(&E->acc, E->obs, j, t, oe_rate(E, j, v));
    }
  }
  if ((st = martello_eval_energy(E->ev, u, v, &ke1, &dummy)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: energy evaluation failed", E->name);
  E->e_impact += ke0 - ke1;
  for (int j = 0; j < E->nc; j++) E->act[j] = ACT_NONE;
  E->held_ready = 0;
  if ((st = closed_set_roots(E)) != MARTELLO_OK)
    return oe_fail(E, MARTELLO_ERR_SINGULAR, "%s: redundant closed contacts at t = %.9e s (B^T M^-1 B singular)", E->name, t);
  return oe_hand_work(E);
}

/* The held set's multipliers plus their tension bars into lam and their rates into dlam at
 * (t, u, v): lambda from the state (oe_closed_multipliers), lambda' the multiplier of the jerk,
 * W_H lambda' = -B_H j (the constraints are linear and the mass constant; as c/event_driven.c). */
static int held_values(ode_events *E, double t, const double *u, const double *v, double *lam,
                       double *dlam) {
  int st = oe_closed_multipliers(E, t, u, v);
  if (st == MARTELLO_OK) st = martello_peak_rates(E->ev, t, u, v, E->ar, E->nc, E->nl, E->elc, E->jk);
  if (st == MARTELLO_OK)
    st = martello_impulse_project(E->n, E->mc, E->dlc, TOPOLOGY(E), E->Wc, NULL, E->jk, E->rhs);
  if (st != MARTELLO_OK)
    return oe_fail(E, st, "%s: the held contacts' forces failed at t = %.9e s", E->name, t);
  for (int k = 0; k < E->mc; k++) {
    lam[k] = E->lr[E->lc[k]] + E->lamtol[E->lc[k]];
    dlam[k] = E->rhs[k];
  }
  return MARTELLO_OK;
}

/* held_values at t on the interpolant of the last step. */
static int held_values_at(ode_events *E, double t, double *lam, double *dlam) {
  int st = E->dky(E->ctx, t, 0, E->ytmp);
  if (st != MARTELLO_OK) return st;
  oe_gather(E, N_VGetArrayPointer(E->ytmp), E->uq, E->vq);
  return held_values(E, t, E->uq, E->vq, lam, dlam);
}

/* The extremum of held contact k's multiplier rate on [lo, hi] (the minimum for s = 1, the
 * maximum for s = -1) by golden-section search on the interpolant, stopped as soon as the rate
 * takes the sign -s (a bracket for the zero of the rate): its time in *t_x, and 1 if the rate
 * there has the sign -s. Exact for a rate with at most one extremum inside the step (docs/
 * sundials-ode.md, held contacts). */
static int rate_extremum(ode_events *E, int k, double lo, double hi, double s, double tol, double *t_x,
                         int *found) {
  const double g = 0.5 * (3.0 - sqrt(5.0));
  double a = lo, b = hi, c = a + g * (b - a), d = b - g * (b - a), fc, fd;
  int st;
  *found = 0;
  if ((st = held_values_at(E, c, E->hlm, E->hdm)) != MARTELLO_OK) return st;
  fc = s * E->hdm[k];
  if ((st = held_values_at(E, d, E->hlm, E->hdm)) != MARTELLO_OK) return st;
  fd = s * E->hdm[k];
  for (int it = 0; it < 200 && fc >= 0.0 && fd >= 0.0 && b - a > tol; it++) {
    if (fc <= fd) {
      b = d, d = c, fd = fc, c = a + g * (b - a);
      if ((st = held_values_at(E, c, E->hlm, E->hdm)) != MARTELLO_OK) return st;
      fc = s * E->hdm[k];
    } else {
      a = c, c = d, fc = fd, d = b - g * (b - a);
      if ((st = held_values_at(E, d, E->hlm, E->hdm)) != MARTELLO_OK) return st;
      fd = s * E->hdm[k];
    }
  }
  *t_x = fc <= fd ? c : d;
  *found = fmin(fc, fd) < 0.0;
  return MARTELLO_OK;
}

int oe_held_release(ode_events *E, double t0, double t1, const double *y1, double *t_r) {
  int st, kbest = -1;
  double best = t1;
  if (E->mc == 0 || !(t1 > t0)) return 0;
  oe_gather(E, y1, E->uq, E->vq);
  if ((st = held_values(E, t1, E->uq, E->vq, E->hl1, E->hd1)) != MARTELLO_OK) return st;
  /* the start's values: kept from the last step's end, or (the first step after a restart)
   * from the interpolant */
  if (!E->held_ready && (st = held_values_at(E, t0, E->hl0, E->hd0)) != MARTELLO_OK) return st;
  const double tol = fmax(E->event_tol, 4.0 * DBL_EPSILON * fabs(t1));
  for (int k = 0; k < E->mc; k++) {
    if (!(E->hl0[k] > 0.0 && E->hl1[k] > 0.0)) continue;
    /* an interior minimum of the multiplier is a zero of its rate from - to +; with at most one
     * extremum of the rate inside the step there is one at most, bracketed by [lo, hi]:
     * - at t0, + at t1: the step; + at both ends: from the rate's minimum, if negative, to t1;
     * - at both ends: from t0 to the rate's maximum, if positive; + then -: none */
    double lo = t0, hi = t1, tx;
    int found = 1;
    if (E->hd0[k] >= 0.0 && E->hd1[k] > 0.0) {
      if ((st = rate_extremum(E, k, t0, t1, 1.0, tol, &tx, &found)) != MARTELLO_OK) return st;
      lo = tx;
    } else if (E->hd0[k] < 0.0 && E->hd1[k] <= 0.0) {
      if ((st = rate_extremum(E, k, t0, t1, -1.0, tol, &tx, &found)) != MARTELLO_OK) return st;
      hi = tx;
    } else if (!(E->hd0[k] < 0.0 && E->hd1[k] > 0.0)) {
      continue;
    }
    if (!found) continue;
    for (int it = 0; it < 200 && hi - lo > tol; it++) {
      const double tm = 0.5 * (lo + hi);
      if ((st = held_values_at(E, tm, E->hlm, E->hdm)) != MARTELLO_OK) return st;
      if (E->hdm[k] < 0.0) lo = tm; else hi = tm;
    }
    if ((st = held_values_at(E, hi, E->hlm, E->hdm)) != MARTELLO_OK) return st;
    if (!(E->hlm[k] < 0.0)) continue;       /* the minimum stays compressive */
    lo = t0;
    for (int it = 0; it < 200 && hi - lo > tol; it++) {
      const double tm = 0.5 * (lo + hi);
      if ((st = held_values_at(E, tm, E->hlm, E->hdm)) != MARTELLO_OK) return st;
      if (E->hlm[k] > 0.0) lo = tm; else hi = tm;
    }
    if (kbest < 0 || hi < best) {
      best = hi;
      kbest = k;
    }
  }
  if (kbest >= 0) {
    E->act[E->rig_con[E->lc[kbest]]] = ACT_RELEASE;
    *t_r = best;
    return 1;
  }
  double *tmp = E->hl0; E->hl0 = E->hl1; E->hl1 = tmp;
  tmp = E->hd0; E->hd0 = E->hd1; E->hd1 = tmp;
  E->held_ready = 1;
  return 0;
}

int oe_initial_contacts(ode_events *E, const double *u0, const double *v0) {
  double vtol = speed_tol(E, v0);
  for (int j = 0; j < E->nc; j++) {
    double d = oe_pen(E, j, u0), w = oe_rate(E, j, v0);
    if (E->rig[j] < 0) {
      if (d == 0.0 && w > 0.0) E->act[j] = ACT_ONSET;
    } else {
      double htol = oe_position_tol(E, j, u0);
      if (d > htol)
        return oe_fail(E, MARTELLO_ERR_ARGUMENT, "contact %d starts penetrated by %.3e m (rigid contacts need delta <= 0 at t = 0)", j, d);
      if (d >= -htol && w >= -vtol) E->act[j] = ACT_IMPACT;
    }
  }
  return MARTELLO_OK;
}

int oe_restart_progress(ode_events *E, double t) {
  E->same_time = t - E->t_prev_restart <= 1e-12 * fmax(fabs(t), E->out_dt) ? E->same_time + 1 : 0;
  E->t_prev_restart = t;
  if (E->same_time > 8 * (E->nc + 2))
    return oe_fail(E, MARTELLO_ERR_NOT_CONVERGED, "%s: contact events keep recurring at t = %.9e s without progress", E->name, t);
  return MARTELLO_OK;
}

/* ---- events inside the steps (docs/sundials-ode.md, events inside the steps) -------------------------
 * Where a law's force is continuous at its switches, the integrator steps across them and its
 * error control takes the kink (a jump of a higher derivative); nothing stops or restarts. After
 * each step the gap of every such contact is compared at the two ends of the stretch (O(1) a
 * contact); where it changes sign, or its rate does with an extremum that may cross, the
 * crossing is found on the interpolant of the step, restricted to the contact's two nodes: the
 * Taylor coefficients of y at the stretch's end, read once a step (degree + 1 calls of the
 * interpolant, O(n)), make each evaluation of one gap O(degree). An event thus costs O(1), not a
 * restart of the whole state. */

/* The Taylor coefficients y^(k)(t_step)/k! of every node's u and v at the end of the last step,
 * k = 0 .. degree, once a step (the same polynomial for every stretch of the step). */
static int taylor(ode_events *E) {
  if (E->tay_ready) return MARTELLO_OK;
  const double t1 = E->t_step;
  int q = E->degree(E->ctx);
  if (q > OE_QMAX) q = OE_QMAX;
  if (q < 1) q = 1;
  double fact = 1.0;
  for (int k = 0; k <= q; k++) {
    if (k > 0) fact *= (double)k;
    int st = E->dky(E->ctx, t1, k, E->ytmp);
    if (st != MARTELLO_OK) return st;
    const double *y = N_VGetArrayPointer(E->ytmp);
    double *cu = E->tay_u + (size_t)k * (size_t)E->n, *cv = E->tay_v + (size_t)k * (size_t)E->n;
    for (int i = 0; i < E->n; i++) {
      cu[i] = y[E->iu[i]] / fact;
      cv[i] = y[E->iv[i]] / fact;
    }
  }
  E->tay_q = q;
  E->tay_ready = 1;
  return MARTELLO_OK;
}

/* Node i's polynomial (coefficients c, stride n) at s = t - t1 (deriv 0) or its derivative. */
static double tay(const double *c, int n, int i, int q, double s, int deriv) {
  double p = 0.0;
  if (deriv == 0) {
    for (int k = q; k >= 0; k--) p = p * s + c[(size_t)k * (size_t)n + (size_t)i];
  } else {
    for (int k = q; k >= 1; k--) p = p * s + (double)k * c[(size_t)k * (size_t)n + (size_t)i];
  }
  return p;
}

/* Contact j's gap (what = 0) or its rate (1) at t on the interpolant (taylor ready). */
static double gap_at(const ode_events *E, int j, double t, int what) {
  const double s = t - E->t_step, *c = what == 0 ? E->tay_u : E->tay_v;
  double x = 0.0;
  for (int k = E->con.first[j]; k < E->con.first[j + 1]; k++)
    x += E->con.coef[k] * tay(c, E->n, E->con.node[k], E->tay_q, s, 0);
  return what == 0 ? x - E->gap[j] : x;
}

/* The time in [lo, hi] where contact j's gap (what = 0) or rate (1) leaves the side it has at lo
 * (lo_positive: > 0 there, as the state at lo says), by bisection to event_tol: the first time on
 * the far side. The side at lo is the state's, not the polynomial's: the two differ by rounding
 * where the gap is 0 at lo (an output row at the touch), and the polynomial's would bracket
 * nothing and return hi, a whole step late. */
static double crossing(const ode_events *E, int j, int what, int lo_positive, double lo, double hi) {
  for (int it = 0; it < 200 && hi - lo > fmax(E->event_tol, 4.0 * DBL_EPSILON * fabs(hi)); it++) {
    const double tm = 0.5 * (lo + hi);
    if ((gap_at(E, j, tm, what) > 0.0) == lo_positive) lo = tm; else hi = tm;
  }
  return hi;
}

static void add_event(ode_events *E, double t, int j, int open) {
  E->ev_t[E->nev] = t;
  E->ev_j[E->nev] = j;
  E->ev_k[E->nev++] = open;
}

static int by_time(const void *x, const void *y) {
  const double *a = x, *b = y;
  return (*a > *b) - (*a < *b);
}

int oe_inner_events(ode_events *E, double t0, double t1, const double *y1) {
  int st;
  E->nev = 0;
  if (!E->smooth || !(t1 > t0)) return MARTELLO_OK;
  oe_gather(E, y1, E->uq, E->vq);
  for (int j = 0; j < E->nc; j++) {
    if (!E->cont[j]) continue;
    const double d0 = E->d_last[j], r0 = E->r_last[j];
    const double d1 = oe_pen(E, j, E->uq), r1 = oe_rate(E, j, E->vq);
    const int in0 = d0 > 0.0, in1 = d1 > 0.0;
    /* an extremum inside that may cross: approaching then receding while open at both ends,
     * or the reverse while in contact at both */
    const int turn = in0 == in1 && (in0 ? (r0 < 0.0 && r1 >= 0.0) : (r0 > 0.0 && r1 <= 0.0));
    if (in0 == in1 && !turn) continue;
    if ((st = taylor(E)) != MARTELLO_OK) return st;
    if (in0 != in1) {
      add_event(E, crossing(E, j, 0, in0, t0, t1), j, in1);
      continue;
    }
    const double tx = crossing(E, j, 1, r0 > 0.0, t0, t1), dx = gap_at(E, j, tx, 0);
    if ((dx > 0.0) == in0) continue;          /* the extremum stays on its side */
    add_event(E, crossing(E, j, 0, in0, t0, tx), j, !in0);
    if (!in0) add_event(E, tx, j, -1);        /* the peak penetration of the touch */
    add_event(E, crossing(E, j, 0, !in0, tx, t1), j, in0);
  }
  /* in time order (an event's three fields sort together) */
  if (E->nev > 1) {
    double *rows = malloc(sizeof(double) * 3 * (size_t)E->nev);
    if (!rows) return oe_fail_memory(E, "the events of a step", 3.0 * sizeof(double) * E->nev);
    for (int k = 0; k < E->nev; k++) {
      rows[3 * k] = E->ev_t[k];
      rows[3 * k + 1] = E->ev_j[k];
      rows[3 * k + 2] = E->ev_k[k];
    }
    qsort(rows, (size_t)E->nev, 3 * sizeof(double), by_time);
    for (int k = 0; k < E->nev; k++) {
      E->ev_t[k] = rows[3 * k];
      E->ev_j[k] = (int)rows[3 * k + 1];
      E->ev_k[k] = (int)rows[3 * k + 2];
    }
    free(rows);
  }
  for (int k = 0; k < E->nev; k++) {
    const int j = E->ev_j[k], touching = martello_observer_in_phase(E->obs, oe_gcon(E, j));
    const double t = E->ev_t[k];
    if (E->ev_k[k] < 0) {
      if (touching && (st = martello_observer_peak(E->obs, MARTELLO_PEAK_PEN, oe_gcon(E, j), gap_at(E, j, t, 0))) != MARTELLO_OK)
        return oe_fail(E, st, "%s: martello_observer_peak failed", E->name);
      continue;
    }
    if (E->ev_k[k] == touching) continue;     /* the observer has it already */
    const double w = gap_at(E, j, t, 1);
    if ((st = martello_observer_set_phase(E->obs, oe_gcon(E, j), E->ev_k[k], t, w)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: martello_observer_set_phase failed", E->name);
    if (E->vin[j] == 0.0) E->vin_j[E->nvin++] = j;     /* listed once until the commit */
    /* for the commit (Hunt-Crossley's v_in); -1: listed, no onset */
    E->vin[j] = E->ev_k[k] ? fmax(w, DBL_MIN) : -1.0;
    E->events++;
  }
  return MARTELLO_OK;
}

void oe_new_step(ode_events *E, double t_step) {
  E->t_step = t_step;
  E->tay_ready = 0;
}

void oe_accepted(ode_events *E, const double *y) {
  oe_gather(E, y, E->uq, E->vq);
  memcpy(E->v_last, E->vq, sizeof(double) * (size_t)E->n);
  if (!E->smooth) return;
  for (int j = 0; j < E->nc; j++) {
    E->d_last[j] = oe_pen(E, j, E->uq);
    E->r_last[j] = oe_rate(E, j, E->vq);
  }
}

int oe_use_smooth(ode_events *E) { return oe_use_smooth_laws(E, MARTELLO_ACROSS_CONTINUOUS); }

int oe_use_smooth_laws(ode_events *E, int laws) {
  double failed = 0.0;
  const size_t ucn = (size_t)E->nc;
  E->cont = oe_take(ucn, sizeof(int), &failed);
  E->d_last = oe_take(ucn, sizeof(double), &failed);
  E->r_last = oe_take(ucn, sizeof(double), &failed);
  E->vin = oe_take(ucn, sizeof(double), &failed);
  E->vin_j = oe_take(ucn, sizeof(int), &failed);
  E->ev_t = oe_take(3 * ucn, sizeof(double), &failed);
  E->ev_j = oe_take(3 * ucn, sizeof(int), &failed);
  E->ev_k = oe_take(3 * ucn, sizeof(int), &failed);
  if (failed > 0.0) return oe_fail_memory(E, "the events inside the steps", failed);
  int st = martello_eval_use_smooth_branches(E->ev, laws, &E->nsw, E->cont);
  if (st != MARTELLO_OK) return oe_fail(E, st, "%s: martello_eval_use_smooth_branches failed", E->name);
  E->smooth = 1;
  if (E->nsw > 0 &&
      (st = martello_eval_switches(E->ev, E->sw_el, E->sw_al, E->sw_be, E->sw_ga)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: martello_eval_switches failed", E->name);
  return MARTELLO_OK;
}

/* ---- set-up --------------------------------------------------------------------------------- */

void oe_release(ode_events *E) {
  void *all[] = {E->mass, E->gap, E->rest, E->fixed, E->el_first, E->el_node, E->el_coef, E->scheme, E->rig,
                 E->rig_con, E->iu, E->iv, E->closed, E->act, E->opened, E->was_closed, E->hit,
                 E->cand, E->q, E->w0, E->w_in, E->w_out, E->u, E->v, E->a, E->x, E->uq, E->vq,
                 E->fint, E->fext, E->force, E->lam, E->S, E->rhs, E->cols, E->dc, E->aset,
                 E->sw_el, E->sw_al, E->sw_be, E->sw_ga, E->sw_hit, E->lc, E->dlc, E->Wc, E->ar,
                 E->lr, E->lamtol, E->v_last, E->el0, E->el1, E->elc, E->pv0, E->pa0, E->pj0,
                 E->pv1, E->pa1, E->pj1, E->ua, E->va, E->aa, E->jk, E->cont, E->d_last,
                 E->r_last, E->vin, E->vin_j, E->tay_u, E->tay_v, E->ev_t, E->ev_j, E->ev_k, E->hl0,
                 E->hd0, E->hl1, E->hd1, E->hlm, E->hdm};
  for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) free(all[k]);
  if (E->ev) martello_eval_free(&E->ev);
  martello_accumulation_free(&E->acc);
}

int oe_setup(ode_events *E, martello_model *model, martello_run *run, const char *name) {
  int st, n, nc, ncp;
  double failed = 0.0;
  char what[96];
  martello_settings s;
  E->model = model;
  E->name = name;
  E->t_prev_restart = -1.0;
  snprintf(what, sizeof what, "an array of the %s state", name);
  if ((st = martello_run_settings(run, &s)) != MARTELLO_OK) return st;
  E->rtol = s.rtol;
  E->atol = s.atol;
  E->event_tol = s.event_tol;
  E->t_end = s.t_end;
  E->h_max = s.h_max;
  E->every = s.every;
  E->out_dt = s.dt * s.every;
  E->dt = s.dt;
  if ((st = martello_model_topology(model, &n, &nc, NULL, NULL, NULL, NULL, NULL,
                                    &ncp)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: could not read the model", name);
  E->n = n;
  E->nc = nc;
  E->ncoupling = ncp;
  size_t un = (size_t)n, ucn = (size_t)nc;
  E->mass = oe_take(un, sizeof(double), &failed);
  E->fixed = oe_take(un, sizeof(int), &failed);
  E->scheme = oe_take(ucn, sizeof(int), &failed);
  E->gap = oe_take(ucn, sizeof(double), &failed);
  E->rest = oe_take(ucn, sizeof(double), &failed);
  E->rig = oe_take(ucn, sizeof(int), &failed);
  E->rig_con = oe_take(ucn, sizeof(int), &failed);
  if (failed > 0.0) return oe_fail_memory(E, what, failed);
  if ((st = martello_model_topology(model, &n, &nc, E->mass, E->fixed, E->scheme, E->gap,
                                    E->rest, &ncp)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: could not read the model", name);
  {
    int nl_rows, nterms;
    if ((st = martello_model_elements(model, &nl_rows, &nterms, NULL, NULL, NULL)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: could not read the model", name);
    E->el_first = oe_take((size_t)(nl_rows + nc + 1), sizeof(int), &failed);
    E->el_node = oe_take((size_t)nterms, sizeof(int), &failed);
    E->el_coef = oe_take((size_t)nterms, sizeof(double), &failed);
    if (failed > 0.0) return oe_fail_memory(E, what, failed);
    if ((st = martello_model_elements(model, &nl_rows, &nterms, E->el_first, E->el_node,
                                      E->el_coef)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: could not read the model", name);
    E->elem.first = E->el_first; E->elem.node = E->el_node; E->elem.coef = E->el_coef;
    E->con = E->elem;
    E->con.first = E->el_first + nl_rows;
  }
  E->nr = 0;
  for (int j = 0; j < nc; j++) {
    if (E->scheme[j] == MARTELLO_SCHEME_LAGRANGE || E->scheme[j] == MARTELLO_SCHEME_RESTITUTION) {
      E->rig[j] = E->nr;
      E->rig_con[E->nr++] = j;
    } else if (E->scheme[j] == MARTELLO_SCHEME_PENALTY) {
      E->rig[j] = -1;
    } else {
      return oe_fail(E, MARTELLO_ERR_UNSUPPORTED, "contact %d: this scheme cannot run on %s", j, name);
    }
  }
  size_t nr = (size_t)E->nr;
  E->iu = oe_take(un, sizeof(sunindextype), &failed);
  E->iv = oe_take(un, sizeof(sunindextype), &failed);
  int **per_rigid[] = {&E->closed, &E->opened, &E->was_closed, &E->hit, &E->cand, &E->dc,
                       &E->aset, &E->lc, &E->dlc};
  for (size_t k = 0; k < sizeof per_rigid / sizeof per_rigid[0]; k++)
    *per_rigid[k] = oe_take(nr, sizeof(int), &failed);
  double **per_rigid_d[] = {&E->q, &E->w0, &E->lam, &E->rhs, &E->lr, &E->lamtol,
                            &E->hl0, &E->hd0, &E->hl1, &E->hd1, &E->hlm, &E->hdm};
  for (size_t k = 0; k < sizeof per_rigid_d / sizeof per_rigid_d[0]; k++)
    *per_rigid_d[k] = oe_take(nr, sizeof(double), &failed);
  E->cols = oe_take(nr * un, sizeof(double), &failed);
  E->S = oe_take(nr * nr, sizeof(double), &failed);
  E->Wc = oe_take(nr * nr, sizeof(double), &failed);
  E->act = oe_take(ucn, sizeof(int), &failed);
  E->w_in = oe_take(ucn, sizeof(double), &failed);
  E->w_out = oe_take(ucn, sizeof(double), &failed);
  E->force = oe_take(ucn, sizeof(double), &failed);
  double **per_node[] = {&E->u, &E->v, &E->a, &E->x, &E->uq, &E->vq, &E->fint, &E->fext,
                         &E->ar, &E->v_last, &E->pv0, &E->pa0, &E->pj0, &E->pv1, &E->pa1,
                         &E->pj1, &E->ua, &E->va, &E->aa, &E->jk};
  for (size_t k = 0; k < sizeof per_node / sizeof per_node[0]; k++)
    *per_node[k] = oe_take(un, sizeof(double), &failed);
  /* the interpolant's Taylor coefficients (node extrema, events inside the steps) */
  E->tay_u = oe_take((OE_QMAX + 1) * un, sizeof(double), &failed);
  E->tay_v = oe_take((OE_QMAX + 1) * un, sizeof(double), &failed);
  if (failed > 0.0) return oe_fail_memory(E, what, failed);
  if (martello_accumulation_init(&E->acc, nc, E->t_end) != MARTELLO_OK) {
    snprintf(what, sizeof what, "the accumulation phases of the %s run", name);
    return oe_fail_memory(E, what, (double)nc * sizeof(double));
  }
  if ((st = martello_eval_create(model, &E->ev)) == MARTELLO_ERR_MEMORY) {
    char line[480]; /* the model's message is the line (martello_eval_create) */
    martello_model_message(model, line, (int)sizeof line);
    return martello_observer_fail(E->obs, st, E->t_now, line);
  }
  if (st != MARTELLO_OK) return oe_fail(E, st, "%s: could not create the force evaluator", name);
  if ((st = martello_eval_link_count(E->ev, &E->nl)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: martello_eval_link_count failed", name);
  if (E->nr > 0) {
    double period = DBL_MAX;
    if ((st = martello_eval_load_period(E->ev, &period)) != MARTELLO_OK)
      return oe_fail(E, st, "%s: martello_eval_load_period failed", name);
    E->h_hold = period < DBL_MAX ? period / HOLD_STEPS : 0.0;
  }
  {
    const size_t ne = 4 * (ucn + (size_t)E->nl);
    double **el[] = {&E->el0, &E->el1, &E->elc};
    for (size_t k = 0; k < sizeof el / sizeof el[0]; k++) *el[k] = oe_take(ne, sizeof(double), &failed);
    if (failed > 0.0) return oe_fail_memory(E, what, failed);
  }
  /* every switching surface of the laws is a root: hold them on smooth branches */
  if ((st = martello_eval_use_branches(E->ev, &E->nsw)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: martello_eval_use_branches failed", name);
  E->sw_el = oe_take((size_t)E->nsw, sizeof(int), &failed);
  E->sw_al = oe_take((size_t)E->nsw, sizeof(double), &failed);
  E->sw_be = oe_take((size_t)E->nsw, sizeof(double), &failed);
  E->sw_ga = oe_take((size_t)E->nsw, sizeof(double), &failed);
  E->sw_hit = oe_take((size_t)E->nsw, sizeof(int), &failed);
  if (failed > 0.0) return oe_fail_memory(E, what, failed);
  if (E->nsw > 0 &&
      (st = martello_eval_switches(E->ev, E->sw_el, E->sw_al, E->sw_be, E->sw_ga)) != MARTELLO_OK)
    return oe_fail(E, st, "%s: martello_eval_switches failed", name);
  return MARTELLO_OK;
}
