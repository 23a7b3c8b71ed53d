/* The door between the Fortran kernels and the C integrators (GSL, SUNDIALS): force
 * evaluation of a scene and the observer that measures the run (fortran/observer.f90,
 * docs/run-layer.md). Not part of the public API. Node arrays have length n (0-based
 * nodes), contact arrays length n_contacts; contacts are 0-based. */
#ifndef MARTELLO_INTERNAL_H
#define MARTELLO_INTERNAL_H
#include <math.h>
#include <stdint.h>

#include "martello.h"

typedef struct martello_eval martello_eval;
typedef struct martello_observer martello_observer;

/* The library's one out-of-memory line (fortran/status.f90, docs/behaviour.md "When memory
 * runs out"): what could not be allocated, how many bytes, and the fix (NULL: a smaller
 * scene), into buf (NUL-terminated, truncated to buflen - 1 characters). */
void martello_memory_message(const char *what, double bytes, const char *fix, char *buf,
                             int buflen);

/* history.csv (c/csv_writer.c, docs/results.md): header, a newline, then rows × cols doubles
 * (row-major) as %.17g, commas between, a newline after each row. 0, or an errno value
 * (EINVAL for a bad argument); a partial file may remain on failure (the caller writes into a
 * folder it discards then). */
int martello_write_csv(const char *path, const char *header, const double *data, int64_t rows,
                       int cols);

/* Scene topology for impact laws: fixed[i] is 0/1; restitution[j] is the contact's e (or -1
 * if none given); the contacts' nodes are their rows (martello_model_elements). Pass NULL for
 * what you don't need. */
int martello_model_topology(const martello_model *model, int *n, int *n_contacts, double *mass,
                            int *fixed, int *scheme, double *gap, double *restitution,
                            int *n_couplings);

/* The elements as rows of the constraint operator (fortran/element_rows.f90, docs/buildings.md):
 * element e deforms by G_e x = sum_k coef[k] x[node[k]], k = first[e] .. first[e+1]-1 (0-based
 * nodes; the ground never appears), its force f acts on the nodes as coef[k] f. A node pair is
 * (a, +1), (b, -1); a contact between plan points of two floors has up to six terms. Links are
 * elements 0 .. n_links-1, contact j is element n_links + j. With first, node, coef NULL:
 * only the sizes (n_terms, all elements' terms together). */
int martello_model_elements(const martello_model *model, int *n_links, int *n_terms, int *first,
                            int *node, double *coef);

/* A set of rows (first, node, coef as martello_model_elements gives them; first may point at a
 * later element, e.g. the contacts: first + n_links). */
typedef struct {
  const int *first, *node;
  const double *coef;
} martello_rows;

/* G_e x. */
static inline double martello_rows_dot(const martello_rows *r, int e, const double *x) {
  double s = 0.0;
  int k;
  for (k = r->first[e]; k < r->first[e + 1]; k++) s += r->coef[k] * x[r->node[k]];
  return s;
}

/* sum_k |coef_k x[node_k]|: the magnitude G_e x is computed from. */
static inline double martello_rows_abs(const martello_rows *r, int e, const double *x) {
  double s = 0.0;
  int k;
  for (k = r->first[e]; k < r->first[e + 1]; k++) s += fabs(r->coef[k] * x[r->node[k]]);
  return s;
}

/* max_k |coef_k x[node_k]| (0 for an empty row). */
static inline double martello_rows_max(const martello_rows *r, int e, const double *x) {
  double s = 0.0;
  int k;
  for (k = r->first[e]; k < r->first[e + 1]; k++) s = fmax(s, fabs(r->coef[k] * x[r->node[k]]));
  return s;
}

/* y <- y + f G_e^T. */
static inline void martello_rows_axpy(const martello_rows *r, int e, double f, double *y) {
  int k;
  for (k = r->first[e]; k < r->first[e + 1]; k++) y[r->node[k]] += f * r->coef[k];
}

/* Initial displacements and velocities of every node (fixed nodes: u0, v = 0). */
int martello_model_initial_state(const martello_model *model, double *u0, double *v0);

int martello_eval_create(martello_model *model, martello_eval **ev);
void martello_eval_free(martello_eval **ev);
/* a = M^-1 (f_ext(t) - f_int(u, v)), zero on fixed nodes; penalty contacts included, link
 * history from the last commit. */
int martello_eval_acceleration(martello_eval *ev, double t, const double *u, const double *v,
                               double *a);
int martello_eval_forces(martello_eval *ev, double t, const double *u, const double *v,
                         double *fint, double *fext);
/* x <- M^-1 x on the free nodes (0 on fixed ones). */
int martello_eval_solve_mass(martello_eval *ev, double *x);
/* Accept (u, v) at the end of a step: path-dependent links (hysteresis) commit. */
int martello_eval_commit(martello_eval *ev, const double *u, const double *v);
/* Keep every element state (committed and trial) / bring back the kept ones: an output row inside
 * a step is committed for its own values, then the step's states are restored, so that no later
 * step depends on where the rows fall. */
int martello_eval_save(martello_eval *ev);
int martello_eval_restore(martello_eval *ev);
/* Event-driven integrators: from now on every piecewise-smooth law is held on one smooth
 * branch between located switches (fortran/switching.f90, docs/event-driven.md); branches
 * change at commits past their switches. *nsw: the number of switch slots. */
int martello_eval_use_branches(martello_eval *ev, int *nsw);
/* As martello_eval_use_branches, but the penalty contacts of the class laws stay whole, their
 * kinks inside the integrator's steps (docs/sundials-ode.md, events inside the steps):
 * MARTELLO_ACROSS_CONTINUOUS those whose force is continuous at onset and separation (linear,
 * Hertz, the Hunt-Crossley family), MARTELLO_ACROSS_RATE_BOUNDED those whose force's rate is
 * bounded there too (linear, Hertz with a whole exponent: fortran/contact_laws.f90
 * law_rate_bounded); continuous[j] = 1 for those contacts (n_contacts values). */
enum { MARTELLO_ACROSS_CONTINUOUS = 1, MARTELLO_ACROSS_RATE_BOUNDED = 2 };
int martello_eval_use_smooth_branches(martello_eval *ev, int laws, int *nsw, int *continuous);
/* The approach speed v at the located onset of penalty contact j's phase (committed in contact):
 * the Hunt-Crossley family's v_in. */
int martello_eval_set_onset_speed(martello_eval *ev, int j, double v);
/* The switches of the branches held, g = alpha G_e u + beta G_e v + gamma on the row of
 * element el (martello_model_elements; -1: an unused slot); g > 0: the branch is left.
 * Constant between commits. */
int martello_eval_switches(martello_eval *ev, int *el, double *alpha, double *beta,
                           double *gamma);
/* The first time after t where a load has a kink (a window's start or end, a table sample),
 * or DBL_MAX. */
int martello_eval_next_breakpoint(martello_eval *ev, double t, double *tb);
/* The shortest period of the loads' harmonic terms (a sine's 2 pi/omega, twice a half sine's
 * window), or DBL_MAX: between their kinks the loads are otherwise linear in t. */
int martello_eval_load_period(martello_eval *ev, double *period);
/* power[5] at the last force evaluation: of the external and the internal forces on the free
 * nodes (f . v), and of the dampers, the other links and the penalty contacts (f (v_a - v_b)):
 * the integrands of martello_observer_work's works. */
int martello_eval_power(martello_eval *ev, double power[5]);
int martello_eval_energy(martello_eval *ev, const double *u, const double *v, double *kinetic,
                         double *recoverable);
/* The half-bandwidth kd of the node couplings (fortran/model.f90 model_bandwidth) and 1 if
 * the mass is lumped (no mass couplings: M^-1 diagonal), else 0. */
int martello_eval_bandwidth(martello_eval *ev, int *kd, int *lumped);
/* The tangent stiffness K_t = d f_int/d u and damping C_t = d f_int/d v at (u, v), on the
 * laws' branches held, in LAPACK's general band layout with ldab = 3 kd + 1: K(i, k) (0-based
 * nodes, |i - k| <= kd) at k_band[(2 kd + i - k) + k (3 kd + 1)], n columns. */
int martello_eval_tangent(martello_eval *ev, const double *u, const double *v, double *k_band,
                          double *c_band);
/* The number of links of the scene. */
int martello_eval_link_count(martello_eval *ev, int *n_links);
/* The rates of the peak quantities at the state (t, u, v) with accelerations a, on the laws'
 * branches held (docs/run-layer.md, located peaks): per contact pen = delta, pen_rate, force
 * (penalty contacts; 0 for the others), force_rate = F_delta delta' + F_delta' delta''; per
 * link du, dv, lf (its force), lf_rate = f_du du' + f_du' du''; per node the jerk
 * a' = M^-1 (f_ext' - f_int'), f_int' the sum of the element rates, f_ext' a centred
 * difference in time of the loads. MARTELLO_ERR_SINGULAR for a singular mass matrix. */
int martello_eval_rates(martello_eval *ev, double t, const double *u, const double *v,
                        const double *a, double *pen, double *pen_rate, double *force,
                        double *force_rate, double *du, double *dv, double *lf, double *lf_rate,
                        double *jerk);

/* ---- sub-models for local stepping (fortran/submodel.f90; docs/run-layer.md, "Sub-models for
 * local stepping") ---------------------------------------------------------------------------
 * A cluster's model: its free nodes, the fixed nodes its elements touch, its elements, their
 * loads. Arrays 0-based, parent numbering. */
typedef struct martello_subset_map {
  int n_nodes, n_links, n_contacts; /* of the sub-model */
  int *node;                        /* [n_nodes] parent node of sub node k */
  int *link;                        /* [n_links] parent link of sub link k */
  int *contact;                     /* [n_contacts] parent contact of sub contact k */
  int n_blocks;                     /* stiffness blocks of the sub-model */
  int *block;                       /* [n_blocks] parent block of sub block k */
} martello_subset_map;
/* The sub-model of parent on its free nodes nodes[0..n-1] (any order; a node given twice, a
 * fixed node or one out of range: MARTELLO_ERR_ARGUMENT). Its nodes: those and the fixed nodes
 * their elements touch, in ascending parent number (kd_sub <= kd_parent). Its contacts: every
 * one whose free nodes all lie in nodes[], in the parent's order (one with a free node outside
 * is left out: the caller's open contact); its links, mass couplings and stiffness blocks
 * likewise, but one with a free node outside is refused (it always joins its nodes' cluster).
 * The nodal forces of its nodes, gravity, influence, ground motion, the contacts' effective
 * masses: the parent's. parent must hold no chains per node (martello_model_expand_chains). The
 * message of a refusal: martello_model_message(parent). O(n + the elements they touch): the
 * parent's node incidence is built on the first call and kept in it while it does not grow
 * (with scratch marks: not reentrant on one parent). *sub: freed by martello_model_free; map: zeroed, then filled with malloc'ed arrays
 * (martello_subset_map_free, safe after a failure too). */
int martello_model_subset(martello_model *parent, int n, const int *nodes, martello_model **sub,
                          martello_subset_map *map);
void martello_subset_map_free(martello_subset_map *map);
/* The model's chains (martello_model_add_chain) made into links and contacts one by one, in
 * place, numbered as the run numbers them. */
int martello_model_expand_chains(martello_model *model);
/* The clusters of the model's free nodes: nodes joined by links, mass couplings, stiffness
 * blocks and the contacts with joined[j] != 0 (closed ones; joined NULL: none), each element
 * joining the free nodes of its row (a fixed node or the ground joins nothing). label[i] (n
 * values): node i's cluster, 0 .. *n_clusters - 1 numbered in the order of their first node; -1
 * for a fixed node. O(n + terms) (union-find): on the parent once, on a sub-model for a split. */
int martello_model_clusters(martello_model *model, const int *joined, int *label,
                            int *n_clusters);
/* Copy the state of map's elements -- committed and trial: link histories, forces and branches
 * held; contact penetrations, rates, forces, onset speeds, on/off and branches; stiffness
 * blocks' states -- and of the sub nodes' last loaded (u, v, f_int, f_ext), from the parent's
 * evaluator into the sub-model's (to_sub = 1; also the branch mode of
 * martello_eval_use_branches / use_smooth_branches) or back (to_sub = 0), bit for bit. Call
 * martello_eval_use_smooth_branches(sub) before it, not after (that re-chooses the branches). A
 * contact between two clusters stays in the parent while they advance: its committed state
 * there is stale; commit a merged cluster at its start state after the transfer. */
int martello_eval_state_transfer(martello_eval *parent, martello_eval *sub,
                                 const martello_subset_map *map, int to_sub);

/* The run being filled: its settings, as martello_run_set_settings validated them, and its
 * observer. */
int martello_run_settings(const martello_run *run, martello_settings *settings);
int martello_run_observer(martello_run *run, martello_observer **obs);

/* The observer's contract (docs/run-layer.md); MARTELLO_OK, or MARTELLO_ERR_ARGUMENT for a
 * null handle or a contact out of range, unless said otherwise.
 * begin: the state (u, v) at t = 0 before its first sample (the energies the balance starts
 * from; energies at every sample); advice ends a divergence message. */
int martello_observer_begin(martello_observer *obs, martello_eval *ev, const double *u,
                            const double *v, const char *advice);
/* An accepted state at t, committed in ev, after the phase changes found at t: peaks, phase
 * maxima, energy terms and the divergence test, a history row where recorded. force: the
 * force of each contact that is not a penalty one (the link states, penetrations and
 * penalty forces are read in ev). k: the output grid point t = k dt it lies on, or -1.
 * Returns MARTELLO_ERR_DIVERGED (message set) when the run must stop. */
int martello_observer_sample(martello_observer *obs, martello_eval *ev, double t, const double *u,
                             const double *v, const double *a, const double *force, int k);
/* An output row on the method's interpolant inside a step, as martello_observer_sample but
 * off the energy grid (no largest |balance|, no divergence test) and not a step of the budget:
 * neither depends on the output (docs/run-layer.md, "the energy terms"). */
int martello_observer_row(martello_observer *obs, martello_eval *ev, double t, const double *u,
                          const double *v, const double *a, const double *force, int k);
/* A step at t of a method that samples the scene only where all of it stands at one time (local
 * stepping): counted against the budget (max_steps, max_wall, the progress callback), no sample;
 * MARTELLO_ERR_LIMIT or MARTELLO_ERR_INTERRUPTED (message set) when the run must stop. */
int martello_observer_step(martello_observer *obs, double t);
/* An extremum of node `node`'s displacement located inside an accepted step (the root of its
 * velocity), at t with value u; maximum = 1 for a maximum, 0 for a minimum. From the first
 * call on, u_peak holds located maxima only. */
int martello_observer_extremum(martello_observer *obs, int node, double t, double u, int maximum);
/* The peaks a method locates inside its accepted steps (fortran/run_quantities.f90 PEAK_*):
 * node |v| and |a|, contact delta and force, link |force| and |elongation|. */
enum { MARTELLO_PEAK_V = 1, MARTELLO_PEAK_A, MARTELLO_PEAK_PEN, MARTELLO_PEAK_FORCE,
       MARTELLO_PEAK_LINK_FORCE, MARTELLO_PEAK_LINK_DU };
/* A peak of kind MARTELLO_PEAK_* of item `index` (0-based node, contact or link) located
 * inside an accepted step, value q (signed; delta and the contact force also enter the open
 * phase's maxima). */
int martello_observer_peak(martello_observer *obs, int kind, int index, double q);
/* What a located peak of kind, index must exceed to change the report (|.| for nodes and
 * links; the open phase's maximum for a contact in a phase), into *q. */
int martello_observer_peak_value(martello_observer *obs, int kind, int index, double *q);
/* Located peaks (c/located_peaks.c): the values q and rates r of every quantity of kind k
 * (items count[k]; q0[k] NULL: not tracked) at both ends of a smooth stretch; skip (NULL:
 * none) leaves an item out (e.g. a contact not in contact). probe gives q and r of item j of
 * kind at an interior time t on the method's own solution. */
typedef struct {
  int count[MARTELLO_PEAK_LINK_DU + 1];
  const double *q0[MARTELLO_PEAK_LINK_DU + 1], *r0[MARTELLO_PEAK_LINK_DU + 1],
      *q1[MARTELLO_PEAK_LINK_DU + 1], *r1[MARTELLO_PEAK_LINK_DU + 1];
  int (*skip)(void *ctx, int kind, int index);
  /* the observer's index of item j of kind: global[kind][j] (NULL: j), for a method that
   * integrates part of the scene (docs/sundials-ode.md, local stepping) */
  const int *global[MARTELLO_PEAK_LINK_DU + 1];
} martello_peak_ends;
typedef int (*martello_peak_probe)(void *ctx, double t, int kind, int index, double *q, double *r);
/* Every extremum inside [t0, t1] that can raise a reported peak, located on the method's
 * solution (secant on the rate from the cubic Hermite's root, parabolic value) and handed to
 * the observer (martello_observer_peak). rtol, event_tol: the method's. */
int martello_locate_peaks(martello_observer *obs, const martello_peak_ends *ends, double t0,
                          double t1, double rtol, double event_tol, martello_peak_probe probe,
                          void *ctx);
/* The end of a smooth stretch that ends at an event (an impact, a closing, a release: the
 * state jumps or kinks there, and the sample after it is the state past the event) is a peak
 * candidate of its own: every quantity's value q1 there is handed to the observer. A peak
 * where a velocity jumps -- a node's |v| just before an impact -- is no root of its rate and
 * would otherwise be missed. */
int martello_peak_fold_end(martello_observer *obs, const martello_peak_ends *ends, void *ctx);
/* The rates of one state in the packed layout of the adaptive methods: el holds
 * martello_eval_rates' element outputs in its order (4 blocks of nc, then 4 of nl), jerk the
 * nodes'. */
int martello_peak_rates(martello_eval *ev, double t, const double *u, const double *v,
                        const double *a, int nc, int nl, double *el, double *jerk);
/* The start (end = 0) or end (1) of ends from one state: node v, a, jerk, packed el. */
void martello_peak_ends_set(martello_peak_ends *e, int end, int n, int nc, int nl,
                            const double *v, const double *a, const double *jerk,
                            const double *el);
/* q and r of item j of kind from one state (as martello_peak_ends_set reads them). */
void martello_peak_pick(int kind, int j, int nc, int nl, const double *v, const double *a,
                        const double *jerk, const double *el, double *q, double *r);
/* Work increments since the last call [J], integrated along the method's own solution:
 * external, total internal (f_int . v), of the links other than dampers and of the penalty
 * contacts (martello_eval_power), and the kinetic energy impulses took out. Damping is
 * internal - links - contacts. */
int martello_observer_work(martello_observer *obs, double w_ext, double w_int, double w_links,
                           double w_contact, double w_impact);
/* Contact phases located by the method: open = 1 starts one at t approaching at v, 0 ends
 * the open one at t leaving at v; in_phase is 1 while one is open (else 0). An impact is an
 * instantaneous phase with its penetration and impulse. */
int martello_observer_set_phase(martello_observer *obs, int contact, int open, double t, double v);
int martello_observer_in_phase(const martello_observer *obs, int contact);
int martello_observer_add_impact(martello_observer *obs, int contact, double t, double v_in,
                                 double v_out, double pen, double impulse);
int martello_observer_add_counts(martello_observer *obs, const long long inc[MARTELLO_NCOUNTERS]);
/* The method failed with status at t_reached: returns status once the message is set. A
 * NULL message: a non-finite state, force or work (MARTELLO_ERR_DIVERGED, one wording). */
int martello_observer_fail(martello_observer *obs, int status, double t_reached,
                           const char *message);
/* The run reached t_reached: open phases become events with t_off = -1. */
int martello_observer_finish(martello_observer *obs, double t_reached);

/* ---- the impulse problem (fortran/impulse.f90 through fortran/api_impulse.f90;
 * docs/impulse.md) ----------------------------------------------------------------------------
 * The m contacts of a problem are list[0..m) of the caller's contact rows g (contact j's
 * penetration row G_j, martello_rows); its gap rate is gdot_j = B_j v with B_j = -G_j (v_b - v_a
 * for a node pair; > 0 opening: the penetration rate with the opposite sign), a compressive
 * impulse P >= 0 acts as B_j^T P, and its column C_j = M^-1 B_j^T (martello_eval_solve_mass
 * of -G_j^T) is column col[j] of the column-major n x (any) array cols. The Delassus matrix is W_kl = B_k C_l;
 * matrices are m x m column-major; P, e, lambda, held are per problem contact. Status:
 * MARTELLO_OK, MARTELLO_ERR_SINGULAR (redundant contacts: Newton's law has no solution, or the
 * held set's W is not positive definite), MARTELLO_ERR_NOT_CONVERGED (LCP pivot or sweep
 * limit), MARTELLO_ERR_ARGUMENT (n or m < 0). */
int martello_impulse_delassus(int n, int m, const int *list, const martello_rows *g,
                              const int *col, const double *cols, double *W);
/* Newton's impact law on the m contacts at once, 0 <= gdot+ + e min(gdot-, 0) _|_ P >= 0
 * with gdot- = B v on entry: the impulses P and v <- v + sum_k P_k C_k. */
int martello_impulse_newton(int n, int m, const int *list, const martello_rows *g,
                            const int *col, const double *cols, const double *e, double *v,
                            double *P, int *iterations);
/* The contact forces of contacts at zero gap and gap rate, 0 <= gddot _|_ lambda >= 0 with
 * gddot = B acc + W lambda (acc: the accelerations without them), and the persistent-contact
 * rule: held[k] = 0 iff the solution opens the contact (lambda_k = 0, gddot_k > 0). */
int martello_impulse_contact_forces(int n, int m, const int *list, const martello_rows *g,
                                    const int *col, const double *cols, const double *acc,
                                    double *lambda, int *held, int *iterations);
/* W of contacts held together, Cholesky-factored into L (m x m). */
int martello_impulse_factor(int n, int m, const int *list, const martello_rows *g,
                            const int *col, const double *cols, double *L);
/* With L from martello_impulse_factor: P = W^-1 (target - B x), x <- x + sum_k P_k C_k, the
 * mass-weighted projection onto B x = target (NULL: 0). */
int martello_impulse_project(int n, int m, const int *list, const martello_rows *g,
                             const int *col, const double *cols, const double *L,
                             const double *target, double *x, double *P);
/* The accumulation (Zeno) rule (docs/impulse.md §4): 1 if the impacts of a contact leaving at
 * t with separation speed s >= 0, pressed by the relative acceleration a, restitution e, have
 * accumulated: no rebound (s = 0 or e = 0; *t_inf = t), or a next flight 2 s/a the method does
 * not resolve -- one whose end it does not locate to 1 % of its length from its position error
 * a step d_res and its speed error v_res (adding up over the flight for a method that restarts
 * at order 1 after an impact: restarts = 1, BDF), or shorter than t_res -- while a changes by
 * no more than da over that flight, |da| <= 1 % (1 - e)^2 a, so that the constant-acceleration
 * series predicts the end of the rest to 1 % of the flight. *t_inf = t + 2 s/(a (1 - e)), the
 * accumulation point, HUGE_VAL-like when there is none. */
int martello_impulse_accumulation(double e, double s, double a, double da, double t,
                                  double t_res, double d_res, double v_res, int restarts,
                                  double *t_inf);

/* ---- accumulations of the C integrators (c/accumulation.c, docs/impulse.md §4) ------------
 * The per-contact bookkeeping every C integrator with rigid contacts shares: the rule
 * decided by martello_impulse_accumulation, and the persistent phase of a contact it holds,
 * written to the observer from the predicted accumulation point t_inf (never after t_end),
 * closed no earlier than it opened: a run reports its phases in order. */
typedef struct {
  int nc;          /* contacts */
  double t_end;    /* the run's end: no phase opens at or after it */
  double *t_hold;  /* per contact: where the phase of its last accumulation starts */
} martello_accumulation;
/* For nc contacts of a run ending at t_end; MARTELLO_ERR_MEMORY if t_hold cannot be had. */
int martello_accumulation_init(martello_accumulation *acc, int nc, double t_end);
void martello_accumulation_free(martello_accumulation *acc);
/* The rule for contact j leaving at t (martello_impulse_accumulation with the change da of a
 * over the next flight and the method's resolutions t_res, d_res, v_res, restarts): 1 if its
 * impacts have accumulated, and then its phase start t_inf is kept. */
int martello_accumulation_decide(martello_accumulation *acc, int j, double e, double s,
                                 double a, double da, double t, double t_res, double d_res,
                                 double v_res, int restarts);
/* Contact j (just decided, or touching at rest: t_hold = t) joins the persistent set: its phase
 * opens at its kept t_inf, unless that is not before t_end. */
int martello_accumulation_hold(martello_accumulation *acc, martello_observer *obs, int j);
/* Contact j is persistent from t (touching at rest, or a plastic impact): its phase start. */
void martello_accumulation_at(martello_accumulation *acc, int j, double t);
/* Contact j leaves the persistent set at t, separating at rate v: its open phase closes at
 * max(t, its start). */
int martello_accumulation_release(martello_accumulation *acc, martello_observer *obs, int j,
                                  double t, double v);

/* The C integrators, dispatched by martello_dynamic_run. */
int martello_event_driven_run(martello_model *model, martello_run *run);
int martello_ida_run(martello_model *model, martello_run *run);
int martello_ode_run(martello_model *model, martello_run *run);
/* martello_ode_run with local_stepping: cluster by cluster (c/local_stepping.c). */
int martello_ode_local_run(martello_model *model, martello_run *run);
#endif
