/* Peaks located inside the accepted steps of the adaptive integrators (GSL in
 * c/event_driven.c, IDA, CVODE and ARKODE in c/ode_events.c; docs/run-layer.md, located peaks): one procedure for
 * every scalar quantity of the state the summary reports a peak of — node |v| and |a|,
 * contact penetration and force, link |force| and |elongation|.
 *
 * The method hands each quantity's value q and rate q' at both ends of a smooth stretch
 * [t0, t1] (no switch inside: the laws are held on their branches, so q is smooth there).
 * Where q' changes sign the stretch holds an extremum. Its value on the cubic Hermite of
 * (q, q') is a screen: an extremum that cannot raise the peak the observer holds is left
 * (it could only if the cubic were off by more than its own rise above the ends). The others
 * are located on the method's own solution, through the probe (a state re-integrated from
 * t0, or the integrator's interpolant): secant iterations on q' from the cubic's root, and
 * the value at the last point corrected by the parabola of its rate, q - q'^2/(2 q''), with
 * q'' the secant slope of the rate across the bracket. The error is the method's at the
 * state plus a term cubic in the last correction of the abscissa. */
#include <math.h>
#include <stddef.h>
#include "martello_internal.h"

/* secant iterations on the rate: the abscissa converges superlinearly from the cubic's root */
#define PEAK_ITERATIONS 8

/* The extremum of the cubic Hermite of (q, q') on [0, 1] (step h) where the rate changes
 * sign: its abscissa theta and value (bisection on the quadratic rate). */
static void cubic_extremum(double h, double q0, double r0, double q1, double r1, double *theta,
                           double *value) {
  const double d0 = h * r0, d1 = h * r1;
  const double c2 = 3.0 * (q1 - q0) - 2.0 * d0 - d1, c3 = 2.0 * (q0 - q1) + d0 + d1;
  double lo = 0.0, hi = 1.0, x;
  const int rising = r0 > 0.0;
  int it;
  for (it = 0; it < 60; it++) {
    const double mid = 0.5 * (lo + hi);
    const double rate = d0 + mid * (2.0 * c2 + 3.0 * c3 * mid);
    if ((rate > 0.0) == rising) lo = mid; else hi = mid;
  }
  x = 0.5 * (lo + hi);
  *theta = x;
  *value = q0 + x * (d0 + x * (c2 + x * c3));
}

/* Whether kind peaks in magnitude (nodes, links) or as a maximum (contacts). */
static int by_magnitude(int kind) {
  return kind != MARTELLO_PEAK_PEN && kind != MARTELLO_PEAK_FORCE;
}

int martello_locate_peaks(martello_observer *obs, const martello_peak_ends *ends, double t0,
                          double t1, double rtol, double event_tol, martello_peak_probe probe,
                          void *ctx) {
  const double h = t1 - t0;
  int kind, j, st;
  if (!(h > 0.0)) return MARTELLO_OK;
  for (kind = MARTELLO_PEAK_V; kind <= MARTELLO_PEAK_LINK_DU; kind++) {
    const double *q0 = ends->q0[kind], *r0 = ends->r0[kind], *q1 = ends->q1[kind],
                 *r1 = ends->r1[kind];
    if (q0 == NULL) continue;
    for (j = 0; j < ends->count[kind]; j++) {
      double theta, est, qend, cur, sg, ta, tb, ra, rb, tm, qm, rm, best;
      int it;
      if (!(r0[j] * r1[j] < 0.0)) continue;
      if (!by_magnitude(kind) && !(r0[j] > 0.0)) continue;   /* contacts: a maximum */
      if (ends->skip != NULL && ends->skip(ctx, kind, j)) continue;
      cubic_extremum(h, q0[j], r0[j], q1[j], r1[j], &theta, &est);
      /* in the sense of the peak: +q for a maximum, -q for a minimum of a magnitude */
      sg = (by_magnitude(kind) && r0[j] < 0.0) ? -1.0 : 1.0;
      qend = fmax(sg * q0[j], sg * q1[j]);
      const int g = ends->global[kind] ? ends->global[kind][j] : j;
      st = martello_observer_peak_value(obs, kind, g, &cur);
      if (st != MARTELLO_OK) return st;
      if (sg * est + (sg * est - qend) < cur) continue;
      /* the extremum on the method's solution */
      ta = t0; ra = r0[j]; tb = t1; rb = r1[j];
      tm = t0 + theta * h;
      best = qend;                              /* the largest value met on the solution */
      for (it = 0; it < PEAK_ITERATIONS; it++) {
        double slope, dt, rise;
        st = probe(ctx, tm, kind, j, &qm, &rm);
        if (st != MARTELLO_OK) return st;
        best = fmax(best, sg * qm);
        if ((rm > 0.0) == (ra > 0.0)) { ta = tm; ra = rm; } else { tb = tm; rb = rm; }
        slope = (rb - ra) / (tb - ta);          /* q'' across the bracket (sign -sg) */
        if (!(slope * sg < 0.0)) break;
        dt = -rm / slope;
        rise = 0.5 * sg * rm * dt;              /* -q'^2/(2 q''), in the peak's sense: >= 0 */
        if (fabs(dt) <= event_tol || rise <= 1e-3 * rtol * fabs(qm)) {
          /* converged: the parabola's correction is below the method's error */
          best = fmax(best, sg * qm + rise);
          break;
        }
        tm += dt;
        if (!(tm > ta && tm < tb)) tm = 0.5 * (ta + tb);
      }
      st = martello_observer_peak(obs, kind, g, sg * best);
      if (st != MARTELLO_OK) return st;
    }
  }
  return MARTELLO_OK;
}

int martello_peak_fold_end(martello_observer *obs, const martello_peak_ends *ends, void *ctx) {
  int kind, j, st;
  for (kind = MARTELLO_PEAK_V; kind <= MARTELLO_PEAK_LINK_DU; kind++) {
    const double *q1 = ends->q1[kind];
    if (q1 == NULL) continue;
    for (j = 0; j < ends->count[kind]; j++) {
      if (ends->skip != NULL && ends->skip(ctx, kind, j)) continue;
      const int g = ends->global[kind] ? ends->global[kind][j] : j;
      if ((st = martello_observer_peak(obs, kind, g, q1[j])) != MARTELLO_OK) return st;
    }
  }
  return MARTELLO_OK;
}

/* The block of kind's value (and, one block on, of its rate) in the packed element rates. */
static const double *block(int kind, int nc, int nl, const double *el) {
  switch (kind) {
  case MARTELLO_PEAK_PEN: return el;
  case MARTELLO_PEAK_FORCE: return el + 2 * nc;
  case MARTELLO_PEAK_LINK_DU: return el + 4 * nc;
  default: return el + 4 * nc + 2 * nl;
  }
}

int martello_peak_rates(martello_eval *ev, double t, const double *u, const double *v,
                        const double *a, int nc, int nl, double *el, double *jerk) {
  return martello_eval_rates(ev, t, u, v, a, el, el + nc, el + 2 * nc, el + 3 * nc, el + 4 * nc,
                             el + 4 * nc + nl, el + 4 * nc + 2 * nl, el + 4 * nc + 3 * nl, jerk);
}

void martello_peak_ends_set(martello_peak_ends *e, int end, int n, int nc, int nl,
                            const double *v, const double *a, const double *jerk,
                            const double *el) {
  int k;
  const double **q = end ? e->q1 : e->q0, **r = end ? e->r1 : e->r0;
  e->count[MARTELLO_PEAK_V] = e->count[MARTELLO_PEAK_A] = n;
  q[MARTELLO_PEAK_V] = v; r[MARTELLO_PEAK_V] = a;
  q[MARTELLO_PEAK_A] = a; r[MARTELLO_PEAK_A] = jerk;
  for (k = MARTELLO_PEAK_PEN; k <= MARTELLO_PEAK_LINK_DU; k++) {
    const int items = k <= MARTELLO_PEAK_FORCE ? nc : nl;
    e->count[k] = items;
    q[k] = block(k, nc, nl, el);
    r[k] = q[k] + items;
  }
}

void martello_peak_pick(int kind, int j, int nc, int nl, const double *v, const double *a,
                        const double *jerk, const double *el, double *q, double *r) {
  if (kind == MARTELLO_PEAK_V) {
    *q = v[j]; *r = a[j];
  } else if (kind == MARTELLO_PEAK_A) {
    *q = a[j]; *r = jerk[j];
  } else {
    const double *b = block(kind, nc, nl, el);
    *q = b[j];
    *r = b[(kind <= MARTELLO_PEAK_FORCE ? nc : nl) + j];
  }
}
