/* Ground motion: exact piecewise-linear response spectra (Nigam & Jennings 1969), Fourier
 * amplitude spectra (FFTW) and spectrum-compatible synthesis (SIMQKE scheme, Gasparini &
 * Vanmarcke 1976) with GSL's Mersenne Twister for reproducible phases.
 * The contract of every function is in martello_ground_motion.h. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>
#include <gsl/gsl_rng.h>

#include "martello.h"
#include "martello_ground_motion.h"

#define GM_TWO_PI 6.283185307179586476925286766559
/* Below this w*dt the closed-form step coefficients lose digits (their terms grow like
 * zeta/(w dt)^3 relative to the result); the Taylor series of the matrix exponentials is
 * used instead.  At w dt = 0.5 the series' matrix has norm <= 1.5, 30 terms reach 1e-27. */
#define GM_SERIES_BELOW 0.5
#define GM_SERIES_TERMS 30
/* T <= GM_RIGID_FRACTION * dt is a rigid oscillator (see the header). */
#define GM_RIGID_FRACTION 1e-6
/* Densities of the synthesis' period grid, points per decade: outside the check band
 * [t_min, t_max] (matching only) and inside it, where the deviation is judged.  A record's
 * PSA is a maximum over the peaks of the response, so it has kinks where the time of the
 * largest peak jumps, and the deviation between grid points can exceed its grid values by
 * about (slope) x (half the log step): with 150 per decade (1.5 % steps) by up to 1.3 %, with
 * 600 per decade (0.38 % steps) by up to 0.4 % (10 records, checked on 36000 per decade). */
#define GM_GRID_PER_DECADE 150.0
#define GM_CHECK_PER_DECADE 600.0
/* Corrections without a new best deviation before an attempt restarts with fresh phases. */
#define GM_PATIENCE 10
/* FFT length >= GM_PAD n: the zero padding keeps the circular wrap of the correction filters
 * (impulse responses of several seconds at the longest periods) out of the record. */
#define GM_PAD 4
/* Bins are multiplied by (target/PSA)^1.5, not ^1: the PSA of the enveloped record responds
 * to a change of the stationary signal's spectrum only partly (the envelope smears it over
 * about 1/(plateau length) in frequency).  Measured on 20 seeds of the OPCM 3274 zone 2
 * soil C target (20 s, dt 0.01 s, +-10 % on 0.15-2 s): mean/max corrections 191/806 with
 * exponent 1, 87/235 with 1.5, 76/331 with 2; 2.5 diverged. */
#define GM_OVER_RELAXATION 1.5

/* FFTW's planner is the one part of FFTW that is not thread-safe (FFTW manual, §5.2
 * "Thread safety"); plans are made and destroyed under this lock. */
static pthread_mutex_t gm_fftw_lock = PTHREAD_MUTEX_INITIALIZER;

/* ---------------------------------------------------------------- step coefficients */

/* u_{i+1} = a u_i + b v_i + c p_i + d p_{i+1};  v_{i+1} = ap u_i + bp v_i + cp p_i + dp p_{i+1}
 * for u'' + 2 zeta w u' + w^2 u = p(t), p linear over the step (Chopra, Table 5.2.1, m = 1). */
typedef struct {
  double a, b, c, d, ap, bp, cp, dp;
} gm_step;

static void gm_step_closed_form(double w, double zeta, double h, gm_step *s) {
  const double q = sqrt(1.0 - zeta * zeta);
  const double wd = w * q;
  const double e = exp(-zeta * w * h);
  const double sn = sin(wd * h), cs = cos(wd * h);
  const double r = zeta / q;
  const double k = w * w;
  const double z2 = 2.0 * zeta / (w * h);
  s->a = e * (r * sn + cs);
  s->b = e * sn / wd;
  s->c = (z2 + e * (((1.0 - 2.0 * zeta * zeta) / (wd * h) - r) * sn - (1.0 + z2) * cs)) / k;
  s->d = (1.0 - z2 + e * ((2.0 * zeta * zeta - 1.0) / (wd * h) * sn + z2 * cs)) / k;
  s->ap = -e * (w / q) * sn;
  s->bp = e * (cs - r * sn);
  s->cp = (-1.0 / h + e * ((w / q + zeta / (h * q)) * sn + cs / h)) / k;
  s->dp = (1.0 - e * (r * sn + cs)) / (k * h);
}

/* The same map from the Taylor series of exp(sK), s = w h, in the scaled state y = (w u, v):
 * y' = w K y + e2 p with K = [[0, 1], [-1, -2 zeta]], so over one step
 *   y_{i+1} = E y_i + g0 p_i + g1 p_{i+1},
 *   E = sum M^k/k!,  g0 = h sum (k+1)/(k+2)! M^k e2,  g1 = h sum 1/(k+2)! M^k e2,  M = sK
 * (the integrals of exp(M(1 - x)) (1 - x) and exp(M(1 - x)) x over x in [0, 1]). */
static void gm_step_series(double w, double zeta, double h, gm_step *s) {
  const double sw = w * h;
  const double m11 = 0.0, m12 = sw, m21 = -sw, m22 = -2.0 * zeta * sw;
  double p11 = 1.0, p12 = 0.0, p21 = 0.0, p22 = 1.0; /* M^k */
  double e11 = 0.0, e12 = 0.0, e21 = 0.0, e22 = 0.0;
  double g0u = 0.0, g0v = 0.0, g1u = 0.0, g1v = 0.0;
  double inv_kfact = 1.0; /* 1/k! */
  for (int k = 0; k < GM_SERIES_TERMS; ++k) {
    const double inv_k2fact = inv_kfact / ((k + 1.0) * (k + 2.0)); /* 1/(k+2)! */
    e11 += p11 * inv_kfact;
    e12 += p12 * inv_kfact;
    e21 += p21 * inv_kfact;
    e22 += p22 * inv_kfact;
    g0u += p12 * (k + 1.0) * inv_k2fact;
    g0v += p22 * (k + 1.0) * inv_k2fact;
    g1u += p12 * inv_k2fact;
    g1v += p22 * inv_k2fact;
    const double n11 = p11 * m11 + p12 * m21, n12 = p11 * m12 + p12 * m22;
    const double n21 = p21 * m11 + p22 * m21, n22 = p21 * m12 + p22 * m22;
    p11 = n11;
    p12 = n12;
    p21 = n21;
    p22 = n22;
    inv_kfact /= (k + 1.0);
  }
  s->a = e11;
  s->b = e12 / w;
  s->c = h * g0u / w;
  s->d = h * g1u / w;
  s->ap = w * e21;
  s->bp = e22;
  s->cp = h * g0v;
  s->dp = h * g1v;
}

static void gm_step_coefficients(double w, double zeta, double h, gm_step *s) {
  if (w * h >= GM_SERIES_BELOW)
    gm_step_closed_form(w, zeta, h, s);
  else
    gm_step_series(w, zeta, h, s);
}

/* Peak |u| at the samples for p = -ag, from rest. */
static double gm_peak_displacement(const double *ag, int n, const gm_step *s) {
  double u = 0.0, v = 0.0, peak = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const double p0 = -ag[i], p1 = -ag[i + 1];
    const double un = s->a * u + s->b * v + s->c * p0 + s->d * p1;
    const double vn = s->ap * u + s->bp * v + s->cp * p0 + s->dp * p1;
    u = un;
    v = vn;
    if (fabs(u) > peak) peak = fabs(u);
  }
  return peak;
}

static double gm_peak_abs(const double *a, int n) {
  double m = 0.0;
  for (int i = 0; i < n; ++i)
    if (fabs(a[i]) > m) m = fabs(a[i]);
  return m;
}

/* Sd, PSV, PSA of one period; pga = max|ag| passed in (rigid limit). */
static void gm_spectral_values(const double *ag, int n, double dt, double zeta, double period,
                               double pga, double *sd, double *psv, double *psa) {
  if (period == 0.0) {
    *sd = 0.0;
    *psv = 0.0;
    *psa = pga;
    return;
  }
  const double w = GM_TWO_PI / period;
  if (period <= GM_RIGID_FRACTION * dt) {
    *sd = pga / (w * w);
    *psv = pga / w;
    *psa = pga;
    return;
  }
  gm_step s;
  gm_step_coefficients(w, zeta, dt, &s);
  const double d = gm_peak_displacement(ag, n, &s);
  *sd = d;
  *psv = w * d;
  *psa = w * w * d;
}

static int gm_all_finite(const double *x, int n) {
  for (int i = 0; i < n; ++i)
    if (!isfinite(x[i])) return 0;
  return 1;
}

int martello_gm_response_spectrum(const double *ag, int n, double dt, double zeta,
                                  const double *periods, int np, double *sd, double *psv,
                                  double *psa) {
  if (ag == NULL || periods == NULL || n < 1 || np < 0) return MARTELLO_ERR_ARGUMENT;
  if (!(dt > 0.0) || !isfinite(dt)) return MARTELLO_ERR_ARGUMENT;
  if (!(zeta >= 0.0 && zeta < 1.0)) return MARTELLO_ERR_ARGUMENT;
  if (!gm_all_finite(ag, n)) return MARTELLO_ERR_ARGUMENT;
  for (int j = 0; j < np; ++j)
    if (!(periods[j] >= 0.0) || !isfinite(periods[j])) return MARTELLO_ERR_ARGUMENT;
  const double pga = gm_peak_abs(ag, n);
  for (int j = 0; j < np; ++j) {
    double d, v, a;
    gm_spectral_values(ag, n, dt, zeta, periods[j], pga, &d, &v, &a);
    if (sd) sd[j] = d;
    if (psv) psv[j] = v;
    if (psa) psa[j] = a;
  }
  return MARTELLO_OK;
}

/* ---------------------------------------------------------------- Fourier amplitude */

int martello_gm_fourier_amplitude(const double *a, int n, double dt, double *freq, double *amp,
                                  int *nfreq) {
  if (a == NULL || freq == NULL || amp == NULL || nfreq == NULL || n < 1)
    return MARTELLO_ERR_ARGUMENT;
  if (!(dt > 0.0) || !isfinite(dt) || !gm_all_finite(a, n)) return MARTELLO_ERR_ARGUMENT;
  const int nf = n / 2 + 1;
  if (*nfreq < nf) {
    *nfreq = nf;
    return MARTELLO_ERR_ARGUMENT;
  }
  double *in = fftw_alloc_real((size_t)n);
  fftw_complex *out = fftw_alloc_complex((size_t)nf);
  if (in == NULL || out == NULL) {
    fftw_free(in);
    fftw_free(out);
    return MARTELLO_ERR_MEMORY;
  }
  pthread_mutex_lock(&gm_fftw_lock);
  fftw_plan plan = fftw_plan_dft_r2c_1d(n, in, out, FFTW_ESTIMATE);
  pthread_mutex_unlock(&gm_fftw_lock);
  if (plan == NULL) {
    fftw_free(in);
    fftw_free(out);
    return MARTELLO_ERR_EXTERNAL;
  }
  memcpy(in, a, (size_t)n * sizeof *in); /* after planning: ESTIMATE does not touch the
                                            arrays, but other flags would */
  fftw_execute(plan);
  const double df = 1.0 / (n * dt);
  for (int k = 0; k < nf; ++k) {
    freq[k] = k * df;
    amp[k] = dt * hypot(out[k][0], out[k][1]);
  }
  *nfreq = nf;
  pthread_mutex_lock(&gm_fftw_lock);
  fftw_destroy_plan(plan);
  pthread_mutex_unlock(&gm_fftw_lock);
  fftw_free(in);
  fftw_free(out);
  return MARTELLO_OK;
}

/* ---------------------------------------------------------------- synthesis */

static double gm_envelope(const double env[MARTELLO_GM_NENV], double t) {
  const double t1 = env[MARTELLO_GM_ENV_RISE], t2 = env[MARTELLO_GM_ENV_PLATEAU_END];
  if (t < t1) return (t / t1) * (t / t1);
  if (t <= t2) return 1.0;
  return exp(-env[MARTELLO_GM_ENV_DECAY] * (t - t2));
}

/* Linear interpolation of y(x) on increasing x[0..m-1]; held constant outside. */
static double gm_interp(const double *x, const double *y, int m, double xv) {
  if (xv <= x[0]) return y[0];
  if (xv >= x[m - 1]) return y[m - 1];
  int lo = 0, hi = m - 1;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (x[mid] <= xv)
      lo = mid;
    else
      hi = mid;
  }
  const double f = (xv - x[lo]) / (x[hi] - x[lo]);
  return y[lo] + f * (y[hi] - y[lo]);
}

/* Smallest 2^a 3^b 5^c >= m (FFTW is fastest on such sizes). */
static int gm_good_fft_size(int m) {
  for (int c = m;; ++c) {
    int r = c;
    while (r % 2 == 0) r /= 2;
    while (r % 3 == 0) r /= 3;
    while (r % 5 == 0) r /= 5;
    if (r == 1) return c;
  }
}

/* Final velocity (trapezoidal rule) and displacement (exact for piecewise-linear a), from
 * rest: v_{i+1} = v_i + h (a_i + a_{i+1})/2, d_{i+1} = d_i + h v_i + h^2 (a_i/3 + a_{i+1}/6). */
static void gm_final_motion(const double *a, int n, double h, double *v_end, double *d_end) {
  double v = 0.0, d = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    d += h * v + h * h * (a[i] / 3.0 + a[i + 1] / 6.0);
    v += 0.5 * h * (a[i] + a[i + 1]);
  }
  *v_end = v;
  *d_end = d;
}

/* alpha, beta such that a - alpha phi1 - beta phi2 has zero final velocity and displacement
 * (both are linear functionals of a, so the 2x2 system makes them vanish to rounding). */
static int gm_baseline_coefficients(const double *a, int n, double h, const double *phi1,
                                    const double *phi2, double *alpha, double *beta) {
  double v1, d1, v2, d2, va, da;
  gm_final_motion(phi1, n, h, &v1, &d1);
  gm_final_motion(phi2, n, h, &v2, &d2);
  gm_final_motion(a, n, h, &va, &da);
  const double det = v1 * d2 - v2 * d1;
  if (!(fabs(det) > 0.0) || !isfinite(det)) return MARTELLO_ERR_ARGUMENT;
  *alpha = (va * d2 - v2 * da) / det;
  *beta = (v1 * da - va * d1) / det;
  return MARTELLO_OK;
}

/* log-spaced points from x0 to x1 inclusive (x0 < x1), at least `per_decade` per decade,
 * written from out[0]; returns the count.  If out is NULL only counts. */
static int gm_log_segment(double x0, double x1, double per_decade, double *out) {
  const int m = 1 + (int)ceil(per_decade * log10(x1 / x0));
  if (out) {
    for (int i = 0; i < m; ++i) out[i] = x0 * pow(x1 / x0, (double)i / (m - 1));
    out[0] = x0;
    out[m - 1] = x1;
  }
  return m;
}

/* The period grid [ta, t_min] ∪ [t_min, t_max] ∪ [t_max, tb]; *c0, *c1 = index range of the
 * check band.  Returns the count (out NULL: only counts). */
static int gm_period_grid(double ta, double tb, double t_min, double t_max, double *out, int *c0,
                          int *c1) {
  int m = 0;
  if (t_min > ta) m += gm_log_segment(ta, t_min, GM_GRID_PER_DECADE, out ? out + m : NULL) - 1;
  if (c0) *c0 = m;
  m += gm_log_segment(t_min, t_max, GM_CHECK_PER_DECADE, out ? out + m : NULL);
  if (c1) *c1 = m - 1;
  if (tb > t_max) m += gm_log_segment(t_max, tb, GM_GRID_PER_DECADE, out ? out + m - 1 : NULL) - 1;
  return m;
}

/* Matching factor of FFT bin frequency f from the grid ratio (log T interpolation, held
 * beyond the grid), faded to 1 between f_b = 1/tb and f_lo = f_b/2 and equal to 1 below, so
 * that content longer than the target's periods is never amplified iteration after
 * iteration (it would only feed the baseline drift). */
static double gm_bin_factor(const double *lgrid, const double *ratio, int ngrid, double f,
                            double f_b, double f_lo) {
  if (f <= f_lo) return 1.0;
  const double r = gm_interp(lgrid, ratio, ngrid, -log(f));
  if (f >= f_b) return r;
  const double w = 0.5 * (1.0 - cos(0.5 * GM_TWO_PI * (f - f_lo) / (f_b - f_lo)));
  return 1.0 + w * (r - 1.0);
}

typedef struct {
  double *env, *phi2, *sig, *rec, *best, *amp, *grid, *lgrid, *target, *psa, *ratio, *stat;
  fftw_complex *spec;
  fftw_plan forward, backward;
  gsl_rng *rng;
} gm_work;

static void gm_work_free(gm_work *w) {
  free(w->env);
  free(w->phi2);
  free(w->sig);
  free(w->rec);
  free(w->best);
  free(w->amp);
  free(w->grid);
  free(w->lgrid);
  free(w->target);
  free(w->psa);
  free(w->ratio);
  pthread_mutex_lock(&gm_fftw_lock);
  if (w->forward) fftw_destroy_plan(w->forward);
  if (w->backward) fftw_destroy_plan(w->backward);
  pthread_mutex_unlock(&gm_fftw_lock);
  fftw_free(w->stat);
  fftw_free(w->spec);
  if (w->rng) gsl_rng_free(w->rng);
}

int martello_gm_synthesize(const double *target_periods, const double *target_psa,
                           int n_target, double pga, double zeta, double dt, int n,
                           const double envelope[MARTELLO_GM_NENV], double t_min, double t_max,
                           double band, int max_iter, unsigned long seed, double *accel,
                           int *iterations, int *restarts, double *worst_deviation) {
  /* ---- arguments */
  if (target_periods == NULL || target_psa == NULL || envelope == NULL || accel == NULL ||
      iterations == NULL || worst_deviation == NULL)
    return MARTELLO_ERR_ARGUMENT;
  if (n_target < 2 || n < 8 || max_iter < 0) return MARTELLO_ERR_ARGUMENT;
  if (!gm_all_finite(target_periods, n_target) || !gm_all_finite(target_psa, n_target))
    return MARTELLO_ERR_ARGUMENT;
  if (!(target_periods[0] >= 0.0)) return MARTELLO_ERR_ARGUMENT;
  for (int j = 0; j < n_target; ++j) {
    if (!(target_psa[j] > 0.0)) return MARTELLO_ERR_ARGUMENT;
    if (j > 0 && !(target_periods[j] > target_periods[j - 1])) return MARTELLO_ERR_ARGUMENT;
  }
  if (!(pga > 0.0) || !isfinite(pga) || !(dt > 0.0) || !isfinite(dt)) return MARTELLO_ERR_ARGUMENT;
  if (!(zeta >= 0.0 && zeta < 1.0)) return MARTELLO_ERR_ARGUMENT;
  if (!gm_all_finite(envelope, MARTELLO_GM_NENV) || !(envelope[MARTELLO_GM_ENV_RISE] >= 0.0) ||
      !(envelope[MARTELLO_GM_ENV_PLATEAU_END] >= envelope[MARTELLO_GM_ENV_RISE]) ||
      !(envelope[MARTELLO_GM_ENV_DECAY] > 0.0))
    return MARTELLO_ERR_ARGUMENT;
  if (!(band > 0.0) || !isfinite(band)) return MARTELLO_ERR_ARGUMENT;
  const double t_first = target_periods[0] > 0.0 ? target_periods[0] : target_periods[1];
  const double ta = fmax(t_first, 2.0 * dt), tb = target_periods[n_target - 1];
  if (!(t_min > 0.0 && t_min < t_max && t_min >= ta && t_max <= tb)) return MARTELLO_ERR_ARGUMENT;

  /* ---- workspaces and plans, once per call */
  gm_work w;
  memset(&w, 0, sizeof w);
  const int nfft = gm_good_fft_size(GM_PAD * n), nbin = nfft / 2 + 1;
  const int ngrid = gm_period_grid(ta, tb, t_min, t_max, NULL, NULL, NULL);
  const size_t nn = (size_t)n, nb = (size_t)nbin, ng = (size_t)ngrid;
  w.env = malloc(nn * sizeof(double));
  w.phi2 = malloc(nn * sizeof(double));
  w.sig = malloc(nn * sizeof(double));
  w.rec = malloc(nn * sizeof(double));
  w.best = malloc(nn * sizeof(double));
  w.amp = malloc(nb * sizeof(double));
  w.grid = malloc(ng * sizeof(double));
  w.lgrid = malloc(ng * sizeof(double));
  w.target = malloc(ng * sizeof(double));
  w.psa = malloc(ng * sizeof(double));
  w.ratio = malloc(ng * sizeof(double));
  w.stat = fftw_alloc_real((size_t)nfft);
  w.spec = fftw_alloc_complex(nb);
  w.rng = gsl_rng_alloc(gsl_rng_mt19937);
  if (!w.env || !w.phi2 || !w.sig || !w.rec || !w.best || !w.amp || !w.grid || !w.lgrid ||
      !w.target || !w.psa || !w.ratio || !w.stat || !w.spec || !w.rng) {
    gm_work_free(&w);
    return MARTELLO_ERR_MEMORY;
  }
  pthread_mutex_lock(&gm_fftw_lock);
  w.forward = fftw_plan_dft_r2c_1d(nfft, w.stat, w.spec, FFTW_ESTIMATE);
  w.backward = fftw_plan_dft_c2r_1d(nfft, w.spec, w.stat, FFTW_ESTIMATE);
  pthread_mutex_unlock(&gm_fftw_lock);
  if (w.forward == NULL || w.backward == NULL) {
    gm_work_free(&w);
    return MARTELLO_ERR_EXTERNAL;
  }
  gsl_rng_set(w.rng, seed);

  /* ---- fixed data: envelope, baseline shapes, period grid and target on it */
  const double t_end = (n - 1) * dt;
  for (int i = 0; i < n; ++i) {
    w.env[i] = gm_envelope(envelope, i * dt);
    w.phi2[i] = w.env[i] * (i * dt / t_end);
  }
  int c0 = 0, c1 = 0;
  gm_period_grid(ta, tb, t_min, t_max, w.grid, &c0, &c1);
  for (int j = 0; j < ngrid; ++j) {
    w.target[j] = gm_interp(target_periods, target_psa, n_target, w.grid[j]);
    w.lgrid[j] = log(w.grid[j]);
  }
  const double target_tmin = gm_interp(target_periods, target_psa, n_target, t_min);
  const double df = 1.0 / (nfft * dt);
  const double f_b = 1.0 / tb, f_lo = 0.5 * f_b;
  for (int k = 0; k < nbin; ++k) {
    const double f = k * df;
    double a0 = 0.0;
    if (k > 0 && 2 * k != nfft && f > f_lo) {
      a0 = gm_interp(target_periods, target_psa, n_target, fmin(fmax(1.0 / f, ta), tb)) / sqrt(f);
      if (f < f_b) a0 *= 0.5 * (1.0 - cos(0.5 * GM_TWO_PI * (f - f_lo) / (f_b - f_lo)));
    }
    w.amp[k] = a0;
  }

  /* ---- attempts (fresh phases from the same generator stream) and corrections */
  int status = MARTELLO_ERR_NOT_CONVERGED, used = 0, n_restarts = 0;
  double best_dev = INFINITY;
  for (;;) {
    /* 1-2: stationary random-phase signal; the record is I(t) sig(t), scaled to the PGA */
    for (int k = 0; k < nbin; ++k) {
      const double phi = GM_TWO_PI * gsl_rng_uniform(w.rng);
      w.spec[k][0] = w.amp[k] * cos(phi);
      w.spec[k][1] = w.amp[k] * sin(phi);
    }
    fftw_execute(w.backward);
    for (int i = 0; i < n; ++i) w.rec[i] = w.env[i] * w.stat[i];
    const double peak0 = gm_peak_abs(w.rec, n);
    if (!(peak0 > 0.0) || !isfinite(peak0)) {
      status = MARTELLO_ERR_ARGUMENT; /* no frequency inside the target's range */
      break;
    }
    for (int i = 0; i < n; ++i) w.sig[i] = w.stat[i] * (pga / peak0);

    double rho = 1.0, attempt_best = INFINITY;
    int attempt_best_at = 0, restart = 0;
    for (int local = 0;; ++local) {
      /* 3: baseline, folded into sig: I (sig - alpha - beta t/t_end) */
      double alpha, beta;
      for (int i = 0; i < n; ++i) w.rec[i] = w.env[i] * w.sig[i];
      status = gm_baseline_coefficients(w.rec, n, dt, w.env, w.phi2, &alpha, &beta);
      if (status != MARTELLO_OK) break;
      for (int i = 0; i < n; ++i) {
        w.sig[i] -= alpha + beta * (i * dt / t_end);
        w.rec[i] = w.env[i] * w.sig[i];
      }
      /* 4: PGA (the scaled copy is what is judged and returned) */
      const double peak = gm_peak_abs(w.rec, n);
      if (!(peak > 0.0) || !isfinite(peak)) {
        status = MARTELLO_ERR_ARGUMENT;
        break;
      }
      const double g = pga / peak;
      /* 5: spectrum of the unscaled record (the judged one's times 1/g) */
      double dev = 0.0;
      for (int j = 0; j < ngrid; ++j) {
        double sd, sv, sa;
        gm_spectral_values(w.rec, n, dt, zeta, w.grid[j], peak, &sd, &sv, &sa);
        w.psa[j] = sa;
        if (j >= c0 && j <= c1) dev = fmax(dev, fabs(g * sa / w.target[j] - 1.0));
      }
      if (dev < best_dev) {
        best_dev = dev;
        for (int i = 0; i < n; ++i) w.best[i] = g * w.rec[i];
      }
      if (dev < attempt_best) {
        attempt_best = dev;
        attempt_best_at = local;
      }
      if (dev <= band) {
        status = MARTELLO_OK;
        break;
      }
      if (used >= max_iter) {
        status = MARTELLO_ERR_NOT_CONVERGED;
        break;
      }
      if (local - attempt_best_at >= GM_PATIENCE) {
        restart = 1;
        break;
      }
      /* 6: ratio to the matching target: the code target from t_min up; below t_min a ramp
       * from rho*pga at ta to the target at t_min, rho steering the record's PGA to pga */
      for (int j = 0; j < ngrid; ++j) {
        double tm = w.target[j];
        if (w.grid[j] < t_min)
          tm = rho * pga + (target_tmin - rho * pga) * (w.grid[j] - ta) / (t_min - ta);
        w.ratio[j] = pow(tm / w.psa[j], GM_OVER_RELAXATION);
      }
      memcpy(w.stat, w.sig, nn * sizeof(double));
      memset(w.stat + n, 0, (size_t)(nfft - n) * sizeof(double));
      fftw_execute(w.forward);
      for (int k = 1; k < nbin; ++k) {
        const double r = gm_bin_factor(w.lgrid, w.ratio, ngrid, k * df, f_b, f_lo);
        w.spec[k][0] *= r;
        w.spec[k][1] *= r;
      }
      fftw_execute(w.backward); /* unnormalised: c2r(r2c(x)) = nfft x */
      for (int i = 0; i < n; ++i) w.sig[i] = w.stat[i] / nfft;
      rho *= g;
      ++used;
    }
    if (!restart) break;
    ++n_restarts;
  }

  if (status == MARTELLO_OK || status == MARTELLO_ERR_NOT_CONVERGED) {
    memcpy(accel, w.best, nn * sizeof(double));
    *iterations = used;
    if (restarts) *restarts = n_restarts;
    *worst_deviation = best_dev;
  }
  gm_work_free(&w);
  return status;
}
