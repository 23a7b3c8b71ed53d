/* The contact events of the SUNDIALS integrators (IDA in c/ida.c, CVODE and ARKODE in
 * c/sundials_ode.c; docs/ida.md, docs/sundials-ode.md): one copy of what they share.
 *
 * Every one of them integrates the nodes' u and v (at places iu[i], iv[i] of its state y), has
 * an interpolant of its last step (y and its derivatives at any t inside it), and treats the
 * contacts alike: two roots per contact (the gap delta_j and its rate; for a closed rigid
 * contact its multiplier), one per switch slot of the laws' branches; at an event the state is
 * made consistent (penalty phases, impacts by Newton's law on all touching rigid contacts at
 * once, the accumulation rule of c/accumulation.c, releases) and the integrator restarts.
 * Between events every accepted state is a sample of the observer, with the works, the node
 * extrema and the located peaks of the step computed on its interpolant. What differs between
 * the adapters -- the state's layout beyond u and v, the residual or right-hand side, how the
 * integrator restarts and counts -- stays in them. Not part of the public API. */
#ifndef MARTELLO_ODE_EVENTS_H
#define MARTELLO_ODE_EVENTS_H
#include <nvector/nvector_serial.h>

#include "martello_internal.h"

/* Internal to the library: none of these names is exported from libmartello. */
#pragma GCC visibility push(hidden)

/* What happens to a contact at a restart. */
enum { ACT_NONE, ACT_ONSET, ACT_SEPARATION, ACT_IMPACT, ACT_RELEASE };

/* The integrator's interpolant of its last step: the k-th derivative of y at t into out.
 * MARTELLO_OK, or a status once the run has failed with the integrator's message. */
typedef int (*ode_interpolant)(void *ctx, double t, int k, N_Vector out);
/* The polynomial degree of that interpolant (the highest k it answers). */
typedef int (*ode_degree)(void *ctx);
/* The adapter's sample of the observer: the state y (its own layout) at t, an output row k of
 * the grid (k dt) or -1 (docs/sundials-ode.md, output rows). */
typedef int (*ode_sample)(void *ctx, double t, const double *y, int k);

/* The highest degree of an interpolant the events inside a step read (CVODE's Adams: 12). */
#define OE_QMAX 12

typedef struct {
  martello_model *model;
  martello_observer *obs;     /* what the run measures */
  martello_eval *ev;
  const char *name;           /* "IDA", "CVODE", "ARKODE": what the messages say */
  ode_interpolant dky;        /* the adapter's interpolant, called with ctx */
  ode_degree degree;          /* its degree (the events inside a step; NULL: not smooth) */
  void *ctx;
  /* events inside the steps (docs/sundials-ode.md, events inside the steps): smooth = 1 when the laws
   * whose force is continuous at their switches are not held on branches; cont[j] = 1 for
   * such a penalty contact, whose onsets and separations are located after each step on the
   * interpolant, contact by contact (no root, no restart); d_last, r_last its gap and rate at
   * the last accepted state; vin[j] > 0: the onset speed located in the stretch, for the
   * commit, its contact listed in vin_j[0..nvin) until then; the interpolant's Taylor
   * coefficients at the end t_step of the integrator's last step (tay_u, tay_v: k-th coefficient
   * of node i at k n + i, degree tay_q, ready when tay_ready) */
  int smooth, *cont, tay_ready, tay_q, nev, *vin_j, nvin;
  double *d_last, *r_last, *vin, *tay_u, *tay_v, t_step;
  double *ev_t;               /* the stretch's events: time, contact, kind (2 nc at most) */
  int *ev_j, *ev_k;
  /* scene (martello_model_topology) */
  int n, nc, nr, ncoupling, nl;
  double *mass, *gap, *rest;
  int *fixed, *scheme;
  /* the elements' rows (martello_model_elements): elem all of them, con the contacts' */
  int *el_first, *el_node;
  double *el_coef;
  martello_rows elem, con;
  int *rig;                   /* contact -> rigid index, or -1 (penalty) */
  int *rig_con;               /* rigid index -> contact */
  sunindextype *iu, *iv;      /* where u_i, v_i sit in y (the adapter's layout) */
  /* modes */
  int *closed;   /* per rigid contact: constraint active */
  int *act;      /* per contact: ACT_* at the restart being prepared */
  int *opened;   /* per rigid contact: opened by the multiplier check at this restart */
  int *was_closed, *hit, *cand; /* per rigid contact, at an impact */
  double *w_in, *w_out; /* per contact: approach and rebound speed of the impact being resolved */
  /* work */
  double *u, *v, *a, *x, *uq, *vq, *fint, *fext, *force, *lam;
  double *S, *rhs;
  int *aset;
  double *q, *w0;
  /* the impulse problem (c/martello_internal.h): M^-1 B_r^T of every rigid contact (column r,
   * B_r = e_b - e_a), built once; the door lists of the contacts in aset */
  double *cols;
  int cols_ready, *dc;
  /* the switches of the laws' branches (martello_eval_switches), refreshed at every commit:
   * roots 2 nc .. 2 nc + nsw - 1 */
  int nsw, *sw_el;
  double *sw_al, *sw_be, *sw_ga;
  int *sw_hit;   /* per slot: the root finder's direction of a switch reported at the restart
                    time (oe_classify_roots), put past its surface by oe_prepare_restart */
  martello_accumulation acc; /* the accumulation rule's phases (c/accumulation.c) */
  /* the release roots: the closed set at the last restart (its rigid contacts lc[0..mc), their
   * door list dlc and W factored in Wc), the free accelerations ar and the signed multipliers
   * lr of a state, and the tension each needs before it counts (lamtol, per rigid contact) */
  int mc, *lc, *dlc;
  double *Wc, *ar, *lr, *lamtol;
  double *v_last;             /* node velocities at the last accepted state (located extrema) */
  /* located peaks (c/located_peaks.c): element quantities and rates (its packed layout) at the
   * ends of the stretch (0, 1) and at a probe (c); node v, a and jerk at both ends; u, v, a and
   * the jerks of a probe */
  int start_rates;
  double *el0, *el1, *elc, *pv0, *pa0, *pj0, *pv1, *pa1, *pj1, *ua, *va, *aa, *jk;
  N_Vector ytmp, ytd;         /* the interpolant's outputs (the adapter creates them) */
  /* output rows on the interpolant (docs/sundials-ode.md, output rows): the adapter's sample and
   * the state of a row (created by an adapter that steps past its output times) */
  ode_sample sample;
  N_Vector yrow;
  /* settings */
  double rtol, atol, event_tol, t_end, h_max, out_dt, dt;
  double h_hold;              /* the longest step while a rigid contact is held (0: no bound;
                                 oe_max_step) */
  /* the held set's multipliers (plus their tension bars) and their rates at the end of the last
   * step (hl0, hd0; valid while held_ready), of this one (hl1, hd1) and inside it (hlm, hdm):
   * oe_held_release */
  double *hl0, *hd0, *hl1, *hd1, *hlm, *hdm;
  int held_ready;
  int restarts;               /* 1: the integrator restarts at order 1 after an event (BDF;
                                 the accumulation rule's resolution), 0: a one-step method */
  int every;                  /* output intervals dt per stop time out_dt */
  /* works since the last hand-over to the observer: external, internal, of the links other
   * than dampers and of the penalty contacts (quadrature), kinetic energy taken out at
   * restarts */
  double dw_ext, dw_int, dw_links, dw_contact, e_impact;
  /* the observer's numbering of the nodes, contacts and links when the run is a cluster of a
   * larger scene (c/local_stepping.c; NULL: the same numbering) */
  const int *g_node, *g_con, *g_link;
  /* diagnostics */
  double t_now;               /* where the integration stands (the t_reached of a failure) */
  int nan_seen;
  long long events;
  long cnt_last[9];           /* the integrator's counters at the last hand-over */
  int same_time;              /* restarts in a row at one time */
  double t_prev_restart;
} ode_events;

/* The observer's index of node i and of contact j (the cluster's maps, docs/sundials-ode.md,
 * local stepping). */
static inline int oe_gnode(const ode_events *E, int i) { return E->g_node ? E->g_node[i] : i; }
static inline int oe_gcon(const ode_events *E, int j) { return E->g_con ? E->g_con[j] : j; }

/* ---- set-up and failures -------------------------------------------------------------------- */
/* The settings, topology and arrays of a run, its evaluator on smooth branches with their
 * switches; the contact schemes the caller runs: rigid ones (lagrange, restitution) on the
 * rigid index. MARTELLO_OK, or a status once the run has failed. The caller fills iu and iv. */
int oe_setup(ode_events *E, martello_model *model, martello_run *run, const char *name);
void oe_release(ode_events *E);
/* The run fails with code at E->t_now, saying fmt (MARTELLO_ERR_MEMORY: the LCP solver's work
 * arrays, the out-of-memory line). */
int oe_fail(ode_events *E, int code, const char *fmt, ...);
/* The out-of-memory line for what (bytes < 0: allocated inside SUNDIALS, amount not known). */
int oe_fail_memory(ode_events *E, const char *what, double bytes);
/* calloc(count) (at least one element); on failure its size is kept in *failed (the first that
 * failed), for the out-of-memory line. */
void *oe_take(size_t count, size_t size, double *failed);

/* ---- kinematics ----------------------------------------------------------------------------- */
/* delta = (u_a - u_b) - gap, in the kernels' order of operations (fortran/evaluator.f90). */
double oe_pen(const ode_events *E, int j, const double *u);
/* delta' = v_a - v_b. */
double oe_rate(const ode_events *E, int j, const double *v);
void oe_gather(const ode_events *E, const double *y, double *u, double *v);
/* Gap within which a rigid contact touches. */
double oe_position_tol(const ode_events *E, int j, const double *u);
/* Move contact j strictly to side sgn (+1: delta > 0) by the smallest shift of one free node. */
void oe_nudge(ode_events *E, int j, int sgn, double *u);

/* x <- B lambda over the closed rigid contacts (lambda per rigid contact, x per node). */
void oe_apply_B(const ode_events *E, const double *lam, double *x);

/* ---- roots and events ----------------------------------------------------------------------- */
/* The number of root functions: two per contact, one per switch slot. */
int oe_nroots(const ode_events *E);
/* The root functions at (t, u, v): (delta, delta') of open and penalty contacts, (lambda + its
 * tension bar, 1) of closed rigid ones (the state's multipliers, oe_closed_multipliers), then the
 * switches (g > 0: the branch is left). */
int oe_roots(ode_events *E, double t, const double *u, const double *v, double *g);
/* The signed multipliers of the closed set at (t, u, v) into E->lr (compression > 0) and the
 * constrained accelerations into E->ar: W_H lambda = -B_H a_free, a = a_free + M^-1 B_H^T lambda. */
int oe_closed_multipliers(ode_events *E, double t, const double *u, const double *v);
/* Accelerations a with the closed set's forces: a <- a + M^-1 B_H^T lambda, W_H lambda = -B_H a
 * (lambda into E->x; linear in a, so a sum of parts may be constrained part by part). */
int oe_constrain(ode_events *E, double *a);
/* What the roots reported at tret mean: 1 (with *t_r, E->act and E->sw_hit) if the integrator
 * restarts (a contact event or a law's switch), 0 if they were extrema of gaps, < 0 on failure. */
int oe_classify_roots(ode_events *E, double t_last, double tret, const double *y,
                      const int *found, double *t_r);
/* A reported root of an open or penalty contact exactly 0 at the return (identical
 * neighbours): 1 (a restart with no event lets the integrator move away). Closed rigid contacts
 * are the adapter's (their multiplier). */
int oe_root_stays_zero(ode_events *E, const double *y, const int *found);
/* After a step without a root: a contact on the wrong side of its regime (h_last: the last
 * step). 1 with E->act and *t_r if the integrator must restart, 0 if not, < 0 on failure. */
int oe_boundary_events(ode_events *E, double t_last, double tret, const double *y,
                       double h_last, double *t_r);
/* After a step without a root while rigid contacts are held: a multiplier compressive at both
 * ends of [t0, t1] whose rate (from the jerk) turns from negative to positive inside has that
 * minimum located on the interpolant (bracketed by the rate's ends, or by the rate's extremum
 * inside, found by golden section); if it is tensile, 1 with E->act (a release) and *t_r at its
 * first zero. 0 if none, < 0 on failure. Every dip is found when the rate has at most one
 * extremum in a held step: loads whose harmonic terms share one frequency (docs/sundials-ode.md,
 * held contacts). */
int oe_held_release(ode_events *E, double t0, double t1, const double *y1, double *t_r);
/* The contacts at t = 0: penalty contacts at zero gap and closing get an onset; rigid contacts
 * at zero gap that approach or rest are resolved as impacts (one penetrated is refused). */
int oe_initial_contacts(ode_events *E, const double *u0, const double *v0);
/* Make the state (u, v) at a restart at t consistent with E->act: penalty regimes, impacts,
 * closings, releases; commit; the multipliers of the closed set into E->lam and the free
 * accelerations into E->a; the release roots; the works handed over. */
int oe_prepare_restart(ode_events *E, double t, double *u, double *v);
/* A restart at t: MARTELLO_ERR_NOT_CONVERGED (run failed) when events keep recurring at one
 * time without progress. */
int oe_restart_progress(ode_events *E, double t);

/* ---- events inside the steps ---------------------------------------------------------------- */
/* Leave the penalty contacts of the class laws (MARTELLO_ACROSS_*) whole and hold the other laws
 * on branches (martello_eval_use_smooth_branches): those contacts lose their roots, their events
 * are located by oe_inner_events. Call after oe_setup, before the first restart; the adapter
 * sets E->degree. */
int oe_use_smooth_laws(ode_events *E, int laws);
/* oe_use_smooth_laws with every law whose force is continuous at its switches (CVODE, IDA). */
int oe_use_smooth(ode_events *E);
/* The onsets and separations of the continuous contacts inside [t0, t1] (y1: the state at t1),
 * each located on the interpolant of the last step by a scalar search on its own gap (its
 * Taylor coefficients at t1, O(degree) an evaluation), handed to the observer in time order;
 * a contact that touches and leaves inside the stretch also gets its peak penetration. */
int oe_inner_events(ode_events *E, double t0, double t1, const double *y1);
/* An accepted state y (after the observer's sample): the node velocities and the gaps and
 * rates the next stretch starts from. */
void oe_accepted(ode_events *E, const double *y);
/* The integrator has taken a step ending at t_step: its interpolant is new (call once a step,
 * before its stretches). */
void oe_new_step(ode_events *E, double t_step);

/* ---- output rows on the interpolant (docs/sundials-ode.md, output rows) ------------------------ */
/* The output time of grid row k (k every dt, t_end for the last row). */
double oe_output_time(const ode_events *E, int k);
/* The output rows at *t_out < t1 inside the last step, for an adapter whose integrator steps past
 * them: each row's state on the interpolant (into E->yrow), the stretch [*t_last, row] (inner
 * events, extrema, peaks, works), committed and sampled as if a step had ended there (no root
 * lies before t1, so the branches are those of the step: a commit there and one at t1 leave
 * what one at t1 leaves). Moves *t_last, *k_out and *t_out on. */
int oe_rows_inside(ode_events *E, double *t_last, double t1, int *k_out, double *t_out);

/* ---- what the observer is handed ---------------------------------------------------------- */
/* Commit (u, v) in the evaluator and read the switches again (the branches may change). */
int oe_commit(ode_events *E, const double *u, const double *v);
/* The works since the last hand-over (once per commit). */
int oe_hand_work(ode_events *E);
/* The stretch [t0, t1] of the last step, on its interpolant: the works (3-point Gauss), the
 * node extrema against E->v_last (y1: the state at t1) and the located peaks; at_event: the
 * integrator restarts at t1 (its state jumps there), so the end is a peak candidate too
 * (martello_peak_fold_end). */
int oe_stretch(ode_events *E, double t0, double t1, const double *y1, int at_event);
/* After a stretch: its end's rates are the next one's start unless the integrator restarts. */
void oe_keep_end_rates(ode_events *E, int unchanged);
/* The longest step the integrator may take now (0: no limit): the setting h_max and, while a
 * rigid contact is held, a fraction of the loads' shortest harmonic period (docs/sundials-ode.md,
 * held contacts). The adapter sets it at the start and after every restart. */
double oe_max_step(const ode_events *E);
/* The next stop after t: t_to (an output time or t_end), or a kink of the load before it; a
 * kink within 16 eps of t_to is t_to, one within 16 eps after t is skipped. *kink = 1 when the
 * stop is (also) a kink: the integrator restarts there. */
double oe_next_stop(ode_events *E, double t, double t_to, int *kink);
/* The integrator's counters now (MARTELLO_COUNTER_* order; events and chatter ignored): their
 * increase since the last hand-over, and the events, to the run. */
int oe_add_counts(ode_events *E, const long c[9]);
#pragma GCC visibility pop
#endif
