/* martello — ground motion: response spectra, Fourier amplitude spectra and
 * spectrum-compatible synthesis of accelerograms.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Units: any consistent set; martello uses s and m/s^2.  Arrays are plain C arrays of double,
 * time samples a[i] at t = i*dt (i = 0 .. n-1), read as a piecewise-linear function of time.
 * Return codes are those of martello.h: MARTELLO_OK (0) on success, MARTELLO_ERR_ARGUMENT (-1)
 * for a bad argument, MARTELLO_ERR_MEMORY (-2), MARTELLO_ERR_EXTERNAL (-10) when FFTW could
 * not make a plan, MARTELLO_ERR_NOT_CONVERGED (-4) when the synthesis did not reach its band
 * (its outputs are then still filled: see martello_gm_synthesize).
 * No function keeps state between calls; FFTW plans are made and destroyed inside each call,
 * under a lock, because FFTW's planner is not thread-safe. */
#ifndef MARTELLO_GROUND_MOTION_H
#define MARTELLO_GROUND_MOTION_H

#ifdef __cplusplus
extern "C" {
#endif

/* Linear SDOF response spectrum of the ground acceleration ag[0..n-1] (step dt), exact for
 * piecewise-linear ag (Nigam & Jennings 1969; Chopra, Dynamics of Structures, §5.2,
 * Table 5.2.1).  For each period periods[j] (np of them) the relative displacement u of
 * u'' + 2 zeta w u' + w^2 u = -ag(t), w = 2 pi / T, starting at rest, is stepped exactly and
 *   sd[j]  = max_i |u(t_i)|  (over the samples of the record; the free vibration after the
 *            record ends is not followed),
 *   psv[j] = w sd[j],  psa[j] = w^2 sd[j].
 * 0 <= zeta < 1.  periods[j] >= 0; T = 0 is the rigid oscillator: sd = psv = 0 and
 * psa = PGA = max|ag| exactly.  Periods T <= 1e-6 dt (w dt >= 2 pi 1e6) are treated as rigid
 * as well: psa = PGA, sd = PGA/w^2, psv = PGA/w; the dynamic correction there is below
 * 4 zeta/(w dt) <= 1e-6 relative.  Any of sd, psv, psa may be NULL if not wanted.
 * Step coefficients: the closed forms of Chopra's Table 5.2.1 when w dt >= 0.5, else the
 * Taylor series of the same matrix exponentials (the closed forms cancel catastrophically
 * for long periods: their terms grow like 1/(w dt)^3 relative to the result). */
int martello_gm_response_spectrum(const double *ag, int n, double dt, double zeta,
                                  const double *periods, int np, double *sd, double *psv,
                                  double *psa);

/* One-sided Fourier amplitude spectrum of a[0..n-1] (step dt), with FFTW (r2c, FFTW_ESTIMATE):
 *   freq[k] = k / (n dt),  amp[k] = dt |X_k|,  X_k = sum_j a[j] exp(-2 pi i j k / n),
 *   k = 0 .. n/2,
 * i.e. the rectangle-rule approximation of |∫ a(t) exp(-2 pi i f t) dt| (units of a times s).
 * On entry *nfreq is the capacity of freq and amp; on return it is the number of values
 * written, n/2 + 1.  If the capacity is too small nothing is written, *nfreq is set to the
 * size needed and MARTELLO_ERR_ARGUMENT is returned. */
int martello_gm_fourier_amplitude(const double *a, int n, double dt, double *freq, double *amp,
                                  int *nfreq);

/* Slots of the envelope array of martello_gm_synthesize. */
enum { MARTELLO_GM_NENV = 3, MARTELLO_GM_ENV_RISE = 0, MARTELLO_GM_ENV_PLATEAU_END = 1,
       MARTELLO_GM_ENV_DECAY = 2 };

/* Spectrum-compatible accelerogram accel[0..n-1] (step dt) for the target pseudo-acceleration
 * spectrum (target_periods[j], target_psa[j]), j < n_target, periods strictly increasing and
 * >= 0, psa > 0, interpolated linearly in T between the points.
 *
 * Method (SIMQKE, Gasparini & Vanmarcke 1976, with the PGA steered inside the loop):
 *  1. phases phi_k uniform on [0, 2 pi) from GSL's gsl_rng_mt19937 seeded with `seed` (GSL
 *     maps seed 0 to its default 4357); Fourier amplitudes A_k = Sa(1/f_k)/sqrt(f_k) (the
 *     stationary-response relation between a one-sided PSD and the PSA), faded to zero below
 *     half the lowest target frequency 1/T_last;
 *  2. stationary signal sig = FFTW c2r of A_k exp(i phi_k) on N = 2^a 3^b 5^c >= 4n points,
 *     first n samples kept; the record is a(t_i) = I(t_i) sig(t_i) (the envelope below);
 *  3. baseline correction: sig <- sig - (alpha + beta t/t_end), alpha and beta solved so that
 *     the record I sig has zero final velocity (trapezoidal rule) and zero final displacement
 *     (exact integration of the piecewise-linear record); being under the envelope, the
 *     correction leaves the record's quiet start and end alone;
 *  4. the record judged is g a, g = pga / max|a|: its PGA is `pga` (normally the target at
 *     T = 0) to rounding, and scaling keeps final velocity and displacement zero;
 *  5. the zeta-damped PSA on a log-spaced period grid from ta = max(first positive target
 *     period, 2 dt) to the last target period, holding t_min and t_max, >= 600 points per
 *     decade in [t_min, t_max] and >= 150 outside (between grid points the PSA, which has
 *     kinks, can stray a few tenths of a percent further: 0.4 % at most on 10 records);
 *     deviation = max |PSA/target - 1| over the grid points in [t_min, t_max];
 *  6. if deviation <= band: done.  Else every bin of the FFTW r2c transform of sig (zero-padded
 *     to N, so the correction filter does not wrap around) is multiplied by (target/PSA)^1.5
 *     at T = 1/f (over-relaxed: the envelope smears a correction of sig over neighbouring
 *     frequencies; interpolated in log T on the grid, held beyond its ends, faded to 1 below
 *     half the lowest target frequency), c2r back, the envelope re-applied (a = I sig), back
 *     to 3.
 *     Below t_min the matching target is not the code's ramp, which a sampled record cannot
 *     follow (its PSA tends to its own PGA at short periods): it is a ramp from rho*pga at ta
 *     to the target at t_min, and rho <- rho g after each correction steers the record's own
 *     PGA to `pga`, so that the scaling of step 4 does not pull the matched spectrum out of
 *     the band;
 *  7. an attempt whose deviation has not improved for 10 corrections is abandoned and a new
 *     attempt starts at 1 with fresh phases drawn further along the same generator stream
 *     (so a record still depends on the seed alone).
 * The record returned is the best one met (smallest deviation), always after steps 3 and 4,
 * so its PGA is `pga` to rounding and its final velocity and displacement are zero to
 * rounding.  Outputs: *iterations = corrections (step 6) made in all, *restarts = attempts
 * abandoned (may be NULL), *worst_deviation = the deviation of the record returned.
 * The envelope (Jennings, Housner & Tsai 1968 type):
 *   I(t) = (t/t_rise)^2 for t < t_rise, 1 up to t_plateau_end, exp(-decay (t - t_plateau_end))
 *   after; t_rise >= 0, t_plateau_end >= t_rise, decay > 0.
 * 0 < t_min < t_max, with ta <= t_min and t_max <= the last target period; band > 0;
 * max_iter >= 0 is the budget of corrections over all attempts.
 * Returns MARTELLO_OK when the band was met, MARTELLO_ERR_NOT_CONVERGED when the budget ran
 * out first (the outputs are still filled, with the best record met). */
int martello_gm_synthesize(const double *target_periods, const double *target_psa,
                           int n_target, double pga, double zeta, double dt, int n,
                           const double envelope[MARTELLO_GM_NENV], double t_min, double t_max,
                           double band, int max_iter, unsigned long seed, double *accel,
                           int *iterations, int *restarts, double *worst_deviation);

#ifdef __cplusplus
}
#endif
#endif /* MARTELLO_GROUND_MOTION_H */
