/* martello — verification and benchmark suite for contact and impact in structural dynamics.
 * The library's C API. SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Lifecycle (as SUNDIALS' IDACreate ... IDAFree):
 *   martello_model_create -> martello_model_set_node (every node) -> martello_model_add_*
 *   -> martello_static_solve (or a dynamic run) -> martello_model_free.
 * Nodes are numbered from 0; MARTELLO_GROUND (-1) stands for the ground / a rigid wall.
 * Contact sign convention: penetration delta = (u_a - u_b) - gap, contact when delta > 0,
 * the compressive force P >= 0 pushes a back and b forward.
 * Return codes: 0 success, > 0 a non-error outcome, < 0 failure; martello_status_name()
 * names them and martello_model_message() explains the last one of a model.
 * Arrays are plain C arrays of double; parameter slots are given by the MARTELLO_P_* and
 * MARTELLO_L_* indices (0-based). The tables behind every enum (names, values, defaults,
 * ranges, what reads what) are the library's registry: martello_registry_*. */
#ifndef MARTELLO_H
#define MARTELLO_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MARTELLO_GROUND (-1)

/* Every constant below is a row of the library's registry (fortran/registry.f90), which
 * the functions martello_registry_* read at run time: tests/test_registry.py checks each
 * enum of this header against it, both ways. */

/* Status codes (the registry's table "status"; fortran/status.f90 holds the values). */
enum martello_status {
  MARTELLO_OK = 0,
  MARTELLO_ILL_CONDITIONED = 1,     /* solved, but digits were lost: read the message   */
  MARTELLO_ROOT_FOUND = 2,          /* an event stopped the integration                  */
  MARTELLO_ERR_ARGUMENT = -1,       /* a bad argument: the message names it              */
  MARTELLO_ERR_MEMORY = -2,
  MARTELLO_ERR_SINGULAR = -3,       /* singular system (a node held by nothing)          */
  MARTELLO_ERR_NOT_CONVERGED = -4,  /* Newton, active set or Uzawa did not converge      */
  MARTELLO_ERR_DIVERGED = -5,       /* NaN or energy growth beyond the input             */
  MARTELLO_ERR_UNSUPPORTED = -6,    /* scheme/integrator/link not possible here          */
  MARTELLO_ERR_UNSTABLE = -7,       /* explicit step beyond its stability limit          */
  MARTELLO_ERR_LAPACK = -8,
  MARTELLO_ERR_STEP_UNDERFLOW = -9,
  MARTELLO_ERR_EXTERNAL = -10,      /* GSL or SUNDIALS reported a failure                */
  MARTELLO_ERR_STATE = -11,         /* call out of order                                 */
  MARTELLO_ERR_LIMIT = -12,         /* max_steps or max_wall reached before t_end        */
  MARTELLO_ERR_INTERRUPTED = -13    /* stopped by the caller's progress callback         */
};

/* Contact schemes, laws, link kinds and time functions (tables "schemes", "laws", "links",
 * "time_functions"); parameter slots (0-based) of the contact and link arrays (tables
 * "contact_parameters", "link_parameters"); sizes (table "constants"). */
enum { MARTELLO_SCHEME_PENALTY = 1, MARTELLO_SCHEME_LAGRANGE = 2,
       MARTELLO_SCHEME_AUGMENTED_LAGRANGE = 3, MARTELLO_SCHEME_RESTITUTION = 4 };
enum { MARTELLO_LAW_LINEAR = 1, MARTELLO_LAW_HERTZ = 2, MARTELLO_LAW_KELVIN = 3,
       MARTELLO_LAW_HUNT_CROSSLEY = 4, MARTELLO_LAW_LANKARANI_NIKRAVESH = 5,
       MARTELLO_LAW_FLORES = 6, MARTELLO_LAW_GONTHIER = 7, MARTELLO_LAW_HERTZDAMP = 8,
       MARTELLO_LAW_JANKOWSKI = 9 };
/* Slots 5 to 7 are reserved and must be 0: the effective mass m* that the kelvin conversion
 * from a restitution and the jankowski law need is the library's, 1/(B M^-1 B^T) from the
 * node masses and mass couplings (martello_model_effective_masses). */
enum { MARTELLO_NPAR_CONTACT = 8, MARTELLO_P_STIFF = 0, MARTELLO_P_EXPONENT = 1,
       MARTELLO_P_DAMPING = 2, MARTELLO_P_RESTITUTION = 3, MARTELLO_P_CLIP = 4 };
enum { MARTELLO_LINK_SPRING = 1, MARTELLO_LINK_DASHPOT = 2, MARTELLO_LINK_BILINEAR = 3,
       MARTELLO_LINK_FLUID_DAMPER = 4, MARTELLO_LINK_BAR = 5 };
enum { MARTELLO_NPAR_LINK = 6, MARTELLO_L_STIFF = 0, MARTELLO_L_DAMP = 1, MARTELLO_L_YIELD = 2,
       MARTELLO_L_HARDENING = 3, MARTELLO_L_ALPHA = 4, MARTELLO_L_VREG = 5 };
enum { MARTELLO_TF_CONSTANT = 1, MARTELLO_TF_TABLE = 2, MARTELLO_TF_SINE = 3,
       MARTELLO_TF_RECTANGULAR = 4, MARTELLO_TF_HALF_SINE = 5, MARTELLO_NPAR_TF = 5 };

/* ---- library ----------------------------------------------------------------------- */
const char *martello_version(void);
/* Versions of the numerical libraries linked in (GSL, SUNDIALS, FFTW, LAPACK), as text. */
int martello_library_versions(char *buf, int buflen);
const char *martello_status_name(int status);

/* ---- registry ---------------------------------------------------------------------- */
/* The library's tables by name: "tables" lists them all (columns rows, cols; the text of a
 * row is the prefix of that table's C constants, e.g. "MARTELLO_LAW_"). A table has rows
 * (0-based), each with a name (at most 31 characters), a text (at most 159) and cols
 * numbers named by martello_registry_column. Among them: "integrators" (value, family,
 * adaptive), "settings" (default, min, max, min_open, max_open, type: the fields of
 * martello_settings after kind, in order), "reads" (integrator x setting: 1 if read),
 * "compatibility" (integrator x scheme: 1 if it runs), "laws" (value, exponent,
 * exponent_fixed), "history" (per: the column groups of martello_run_history in order,
 * repeated per "history_per"), "counters", "energy", "events" (0-based indices), "status"
 * (text: meaning). Names and texts are copied NUL-terminated; a buffer too short, an
 * unknown table or an index out of range return MARTELLO_ERR_ARGUMENT. NULL name, text or
 * values are skipped. */
int martello_registry_shape(const char *table, int *rows, int *cols);
int martello_registry_column(const char *table, int col, char *name, int namelen);
int martello_registry_entry(const char *table, int row, char *name, int namelen, double *values);
int martello_registry_text(const char *table, int row, char *text, int textlen);
/* The row named name (or MARTELLO_ERR_ARGUMENT and row = -1). */
int martello_registry_find(const char *table, const char *name, int *row);

/* ---- model ------------------------------------------------------------------------- */
typedef struct martello_model martello_model;

int martello_model_create(int n_nodes, int max_links, int max_contacts, int max_forces,
                          int max_mass_couplings, martello_model **model);
void martello_model_free(martello_model **model);
int martello_model_set_node(martello_model *model, int node, double mass, double u0,
                            double v0, int fixed);
int martello_model_add_link(martello_model *model, int kind, int a, int b,
                            const double par[MARTELLO_NPAR_LINK]);
int martello_model_add_contact(martello_model *model, int a, int b, double gap, int scheme,
                               int law, const double par[MARTELLO_NPAR_CONTACT]);
int martello_model_add_mass_coupling(martello_model *model, int a, int b, double value);
/* A link or a contact whose deformation is a combination of several DOFs: sum_k coef[k]
 * u[nodes[k]] over n terms (0-based nodes, -1: the ground, left out), its force f acting on
 * the nodes as coef[k] f -- a contact's penetration is that minus gap. A node pair a, b is the
 * row (a, +1), (b, -1), what martello_model_add_link/_add_contact make; a contact between plan
 * points of two rigid floors is n . (P_a q_a - P_b q_b), six terms (docs/buildings.md). Every
 * integrator, the impulse problem (W = G M^-1 G^T) and the effective masses read rows. */
int martello_model_add_link_row(martello_model *model, int kind, int n, const int *nodes,
                                const double *coef, const double *par);
int martello_model_add_contact_row(martello_model *model, int n, const int *nodes,
                                   const double *coef, double gap, int scheme, int law,
                                   const double *par);
/* A chain held per node (docs/c-api.md "Chains"): nodes first ... first + n - 1 (0-based, set
 * by set_node(s)), node i with a spring k[i] to ground (a bilinear spring when fy and
 * hardening are given), a dashpot c[i] to ground where c[i] > 0 (c NULL: none), and nodes i,
 * i + 1 in contact through gap[i] (n - 1 values; NULL: no contacts) with one scheme, law and
 * par[MARTELLO_NPAR_CONTACT] for all. Its links and contacts are numbered as if added by
 * add_links and add_contacts at this call (the spring, then the dashpot, of each node), and
 * checked as those check them (the message names the chain entry); the model holds them as
 * these arrays, O(1) values per node, not as links and contacts: the fused chain step reads
 * them so; any other method gets them one by one when it runs. They need no capacity at
 * martello_model_create. */
int martello_model_add_chain(martello_model *model, int first, int n, const double *k,
                             const double *c, const double *fy, const double *hardening,
                             const double *gap, int scheme, int law, const double *par);
/* Bulk doors for large models: n entries in one call, each checked exactly as by
 * martello_model_set_node / _add_link / _add_contact, in order (so the model is the one the
 * one-entry calls build). Nodes 0..n-1 are set from mass[i], u0[i], v0[i], fixed[i];
 * par is n rows, row-major (par[i*MARTELLO_NPAR_LINK + j], par[i*MARTELLO_NPAR_CONTACT + j]).
 * The first bad entry stops the call; martello_model_message names its 0-based index. */
int martello_model_set_nodes(martello_model *model, int n, const double *mass, const double *u0,
                             const double *v0, const int *fixed);
int martello_model_add_links(martello_model *model, int n, const int *kind, const int *a,
                             const int *b, const double *par);
int martello_model_add_contacts(martello_model *model, int n, const int *a, const int *b,
                                const double *gap, const int *scheme, const int *law,
                                const double *par);
/* A symmetric stiffness block between n distinct nodes (0-based, no ground): internal force
 * f[nodes[i]] += sum_j (k[i + n*j] u[nodes[j]] + c[i + n*j] v[nodes[j]]) (k, c column-major
 * n x n, exactly symmetric, diag k > 0, diag c >= 0; c may be NULL: undamped) -- a
 * statically condensed structure such as a planar frame on its lateral DOFs
 * (docs/problems.md P10). Every integrator runs it; blocks need no capacity. */
int martello_model_add_stiffness_block(martello_model *model, int n, const int *nodes,
                                       const double *k, const double *c);
int martello_model_set_gravity(martello_model *model, double g);
/* The influence vector iota[n_nodes]: how far each node moves per unit motion along the
 * scene's axis, so that gravity and the ground acceleration load M iota (default 1 for
 * every node; Chopra, Dynamics of Structures, 9.4). A 3D building's floors: cos and sin of
 * the motion's direction on ux and uy, 0 on rz (docs/buildings.md). */
int martello_model_set_influence(martello_model *model, int n, const double *iota);
/* A time function: kind MARTELLO_TF_*, par[MARTELLO_NPAR_TF], and for a table n_table
 * samples (t[i], y[i]) with t strictly increasing (y scaled by par[0]). */
int martello_model_add_nodal_force(martello_model *model, int node, int kind,
                                   const double *par, int n_table, const double *t,
                                   const double *y);
int martello_model_set_ground_acceleration(martello_model *model, int kind,
                                           const double *par, int n_table, const double *t,
                                           const double *y);
int martello_model_message(const martello_model *model, char *buf, int buflen);
/* The effective mass m* = 1/(B M^-1 B^T) of every contact (mstar[n_contacts]): B the
 * contact's row (+1 at a, -1 at b), M the node masses plus mass couplings on the free
 * nodes; a ground or fixed side is infinitely heavy (+inf if neither side moves). */
int martello_model_effective_masses(martello_model *model, double *mstar);

/* ---- static analysis ---------------------------------------------------------------- */
/* Outputs: u[n_nodes]; per contact force[] (P >= 0), penetration[], active[] (0/1);
 * counters[3] = {active-set iterations, Uzawa iterations, linear solves};
 * conditioning[4] = {LAPACK reciprocal condition estimate of the system solved, significant
 * digits lost, max penalty ratio eps/k, reciprocal condition estimate of the penalised
 * stiffness K + eps B B^T (what a primal penalty solve faces)}.
 * Returns MARTELLO_ILL_CONDITIONED (> 0) when more than 8 digits were lost. */
int martello_static_solve(martello_model *model, double tol, int max_iter, double *u,
                          double *force, double *penetration, int *active, int *counters,
                          double *conditioning);

/* ---- dynamic analysis --------------------------------------------------------------- */
/* Lifecycle: martello_run_create -> martello_settings_default + martello_run_set_settings
 * (-> _set_outputs) -> martello_dynamic_run(model, run) -> martello_run_* getters ->
 * martello_run_free. A failed run (status < 0: diverged, unstable, Newton not converged ...)
 * keeps what it computed up to the failure for diagnosis; martello_run_message() says where
 * and why. */
typedef struct martello_run martello_run;

/* Integrators (table "integrators") and their families (table "families"). */
enum { MARTELLO_INT_NEWMARK = 1, MARTELLO_INT_HHT = 2, MARTELLO_INT_GENERALIZED_ALPHA = 3,
       MARTELLO_INT_CENTRAL_DIFFERENCE = 4, MARTELLO_INT_MOREAU_JEAN = 5,
       MARTELLO_INT_NEWMARK_LAGRANGE = 6, MARTELLO_INT_RKF45 = 7, MARTELLO_INT_RK8PD = 8,
       MARTELLO_INT_MSBDF = 9, MARTELLO_INT_IDA = 10, MARTELLO_INT_FAST_NONLINEAR = 11,
       MARTELLO_INT_CVODE = 12, MARTELLO_INT_ARKODE = 13 };
enum { MARTELLO_FAMILY_NEWMARK = 1, MARTELLO_FAMILY_TIME_STEPPING = 2,
       MARTELLO_FAMILY_CONSTRAINED_NEWMARK = 3, MARTELLO_FAMILY_EVENT_DRIVEN = 4,
       MARTELLO_FAMILY_DAE = 5, MARTELLO_FAMILY_MODAL = 6, MARTELLO_FAMILY_ODE = 7 };

/* The settings of a run, field by field the Fortran type integrator_settings_t
 * (fortran/integrator_settings.f90). martello_settings_default fills the registry's
 * defaults (table "settings"); set dt and t_end, then martello_run_set_settings checks every
 * field the integrator reads (table "reads") against its range and names the first one out
 * of it. Fields an integrator does not read are ignored. */
typedef struct martello_settings {
  int kind;                 /* the integrator, MARTELLO_INT_* */
  double dt;                /* fixed step [s]; adaptive integrators: the output interval */
  double t_end;             /* end time [s] */
  double beta;              /* Newmark beta > 0 */
  double gamma;             /* Newmark gamma >= 1/2 */
  double alpha;             /* HHT alpha in [-1/3, 0] */
  double rho_inf;           /* generalized-alpha: spectral radius at infinity, in [0, 1] */
  double tol_residual;      /* Newton: |r|inf <= tol_residual x force scale */
  double tol_increment;     /* Newton: predicted |du|inf <= tol_increment x displacement scale */
  int max_newton;           /* Newton iterations per step */
  bool check_stability;     /* central difference: refuse dt > dt_crit */
  int every;                /* record every n-th step (adaptive: every n-th output time) */
  double divergence_factor; /* diverged when the mechanical energy > factor x (E0 + input) */
  double rtol;              /* adaptive steppers: relative tolerance */
  double atol;              /* adaptive steppers: absolute tolerance */
  double theta;             /* Moreau-Jean theta in [1/2, 1] */
  double event_tol;         /* event location, absolute in time [s] */
  double h_max;             /* adaptive: the largest step [s] (0: no limit) */
  bool fused_chain;         /* Newmark on a chain: the fused chain step (false: general path) */
  double max_steps;         /* steps a run may take (a whole number; the run fails past it) */
  double max_wall;          /* wall-clock seconds a run may take (0: no limit) */
  bool event_split;         /* Newmark family: split a step at a penalty onset/separation */
  int method;               /* cvode, arkode: a value of the table "methods" (0: the default) */
  int modal_vectors;        /* fast-nonlinear: 0 all modes; m > 0: m load-dependent Ritz vectors */
  bool local_stepping;      /* cvode, arkode: integrate cluster by cluster (docs/sundials-ode.md) */
} martello_settings;

/* Indices of martello_run_counters, martello_run_energy and the values of
 * martello_run_events (tables "counters", "energy", "events"). */
enum { MARTELLO_NCOUNTERS = 11, MARTELLO_NENERGY = 9, MARTELLO_NEVENT = 6 };
enum { MARTELLO_COUNTER_STEPS = 0, MARTELLO_COUNTER_REJECTED_STEPS = 1,
       MARTELLO_COUNTER_NEWTON_ITERATIONS = 2, MARTELLO_COUNTER_RESIDUAL_EVALUATIONS = 3,
       MARTELLO_COUNTER_FACTORIZATIONS = 4, MARTELLO_COUNTER_EVENTS = 5,
       MARTELLO_COUNTER_JACOBIAN_EVALUATIONS = 6, MARTELLO_COUNTER_ROOT_EVALUATIONS = 7,
       MARTELLO_COUNTER_CONTACT_CHATTER_RESOLUTIONS = 8, MARTELLO_COUNTER_MODES = 9,
       MARTELLO_COUNTER_FUSED_CHAIN_STEPS = 10 };
enum { MARTELLO_ENERGY_KINETIC = 0, MARTELLO_ENERGY_RECOVERABLE = 1, MARTELLO_ENERGY_INPUT = 2,
       MARTELLO_ENERGY_DAMPING = 3, MARTELLO_ENERGY_PLASTIC = 4, MARTELLO_ENERGY_CONTACT = 5,
       MARTELLO_ENERGY_BALANCE = 6, MARTELLO_ENERGY_INITIAL = 7, MARTELLO_ENERGY_IMPACT = 8 };
enum { MARTELLO_EVENT_T_ON = 0, MARTELLO_EVENT_T_OFF = 1, MARTELLO_EVENT_V_IN = 2,
       MARTELLO_EVENT_V_OUT = 3, MARTELLO_EVENT_MAX_PENETRATION = 4,
       MARTELLO_EVENT_MAX_FORCE = 5 };

int martello_run_create(martello_run **run);
void martello_run_free(martello_run **run);
/* MARTELLO_ERR_ARGUMENT for an unknown kind. */
int martello_settings_default(int kind, martello_settings *settings);
int martello_run_set_settings(martello_run *run, const martello_settings *settings);
int martello_run_set_outputs(martello_run *run, int n_nodes, const int *nodes, int n_contacts,
                             const int *contacts);
/* Links whose force and elongation the history records (0-based; default none). */
int martello_run_set_link_outputs(martello_run *run, int n_links, const int *links);
/* Which contacts' phases martello_run_events lists (docs/results.md): every contact's while
 * the model has at most max_contacts contacts (default 1000; < 0: always); past it, those of
 * the output contacts (martello_run_set_outputs), and of every other contact its first and
 * last phase alone (in that order), so a long pounding chain keeps two rows per contact. */
int martello_run_set_phase_lists(martello_run *run, int max_contacts);
/* What a run tracks (the registry's table "tracking"), an OR of MARTELLO_TRACK_*; default
 * MARTELLO_TRACK_ALL. What it does not track costs no memory: martello_run_peaks,
 * _abs_peaks and _link_peaks give NaN for it, martello_run_events no rows; the number of
 * phases of each contact (impacts) is always counted. */
enum { MARTELLO_TRACK_NODE_PEAKS = 1, MARTELLO_TRACK_LINK_PEAKS = 2,
       MARTELLO_TRACK_CONTACT_PEAKS = 4, MARTELLO_TRACK_PHASES = 8, MARTELLO_TRACK_ALL = 15 };
int martello_run_set_tracking(martello_run *run, int what);
/* Linear functionals q = R.u of the state tracked at every accepted sample, whatever the
 * history records (docs/results.md, "Frames and buildings"): n rows of R in compressed rows
 * (ptr[n+1] with ptr[0] = 0, col[ptr[n]] the 0-based nodes, val the coefficients), and np
 * pairs of rows (pairs[2 np], 0-based) whose resultant sqrt(q_a^2 + q_b^2) is tracked.
 * Their extremes: martello_run_functionals. n = 0 (the default): none. */
int martello_run_set_functionals(martello_run *run, int n, const int *ptr, const int *col,
                                 const double *val, int np, const int *pairs);
/* The step trace (docs/results.md "Step trace"): contact (0-based; < 0: none, the default)
 * whose force the run keeps, with the kinetic and recoverable energies (and the traced nodes'
 * u), at every grid point t = k dt of a fixed-step method, whatever the history records:
 * martello_run_trace. */
int martello_run_set_trace(martello_run *run, int contact);
/* The n nodes (0-based; default none) whose displacement u the step trace holds too. */
int martello_run_set_trace_nodes(martello_run *run, int n, const int *nodes);
/* ---- closed forms of catalogue problems (docs/c-api.md "Closed forms") ------------------
 * The closed form `name` at the n_par parameters par: out (4 values) receives its *n_out
 * values. MARTELLO_ERR_ARGUMENT for an unknown name, a wrong parameter count or parameters
 * outside the form's domain. */
int martello_closed_form(const char *name, const double *par, int n_par, double out[4],
                         int *n_out);

/* Progress of a running martello_dynamic_run: called about four times a second with user,
 * the simulated time t of t_end, the steps taken and the wall-clock seconds since the start.
 * Return 0 to go on; anything else stops the run at once with MARTELLO_ERR_INTERRUPTED (the
 * results so far are not a result). A NULL callback removes it. */
typedef int (*martello_progress_fn)(void *user, double t, double t_end, long long steps,
                                    double elapsed);
int martello_run_set_progress(martello_run *run, martello_progress_fn callback, void *user);
int martello_dynamic_run(martello_model *model, martello_run *run);
int martello_run_message(const martello_run *run, char *buf, int buflen);
/* History: rows records of cols values, record after record, in the column groups of the
 * table "history": t, then u, v, a of each output node (all u first, then all v, then all
 * a), then penetration and force of each output contact, then force and elongation of each
 * output link (NaN where an integrator does not report links), then the energy terms. */
int martello_run_history_shape(const martello_run *run, int *rows, int *cols);
int martello_run_history(const martello_run *run, double *buf);
/* Contact phases: n on return; with non-NULL arrays also contact[n] and
 * values[n][MARTELLO_NEVENT], indexed by MARTELLO_EVENT_* (t_off = -1: open at the end). */
int martello_run_events(const martello_run *run, int *n, int *contacts, double *values);
/* counters indexed by MARTELLO_COUNTER_* (chatter resolutions: steps where a contact was
 * held open, see docs/integrators.md) */
int martello_run_counters(const martello_run *run, long long counters[MARTELLO_NCOUNTERS]);
/* Per node: extremes over the steps, and the largest local maximum of u (u_peak at t_peak;
 * t_peak = -1 if u never turned back); per contact: max penetration, max force and the number
 * of contact phases; every peak located inside the steps (docs/results.md). Any output may be
 * NULL: not written. What the run does not track is NaN (martello_run_set_tracking). */
int martello_run_peaks(const martello_run *run, double *u_max, double *u_min, double *v_absmax,
                       double *a_absmax, double *pen_max, double *force_max, int *impacts,
                       double *u_peak, double *t_peak);
/* Per node: the largest |u| and its time t_absmax: at the steps, at the extrema the adaptive
 * integrators locate, and on each fixed step's cubic Hermite on (u, v) (docs/results.md).
 * NULL: not written. */
int martello_run_abs_peaks(const martello_run *run, double *u_absmax, double *t_absmax);
/* energy indexed by MARTELLO_ENERGY_*; extra = {max |balance|, omega_max, dt_crit
 * (explicit), time reached} */
int martello_run_energy(const martello_run *run, double energy[MARTELLO_NENERGY], double extra[4]);
/* Per link: max |force| and max |elongation| over the run (NaN if the integrator does not
 * report link states, or the run does not track them). NULL: not written. */
int martello_run_link_peaks(const martello_run *run, double *force_absmax, double *elongation_absmax);
/* Per functional (martello_run_set_functionals): its largest and smallest value and their
 * times, at the samples and inside the stretches between them (the cubic Hermite of (q, R.v));
 * per pair the largest resultant at the samples and its time. Times -1: no sample. */
int martello_run_functionals(const martello_run *run, double *q_max, double *t_max, double *q_min,
                             double *t_min, double *res_max, double *t_res);
/* The step trace (martello_run_set_trace): n grid points on return; with a non-NULL buf also
 * buf[n][4 + m] = {t, the contact's force, kinetic energy, recoverable energy, u of the m
 * traced nodes (martello_run_set_trace_nodes)}. */
int martello_run_trace(const martello_run *run, int *n, double *buf);

#ifdef __cplusplus
}
#endif
#endif /* MARTELLO_H */
