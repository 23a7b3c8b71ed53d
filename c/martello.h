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
 * MARTELLO_L_* indices (0-based). */
#ifndef MARTELLO_H
#define MARTELLO_H

#ifdef __cplusplus
extern "C" {
#endif

#define MARTELLO_GROUND (-1)

/* Status codes (values fixed; fortran/status.f90 mirrors them). */
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
  MARTELLO_ERR_STATE = -11          /* call out of order                                 */
};

/* Contact schemes, laws, link kinds and time functions (values are the kernels';
 * martello_constant() returns them by name). */
enum { MARTELLO_SCHEME_PENALTY = 1, MARTELLO_SCHEME_LAGRANGE = 2,
       MARTELLO_SCHEME_AUGMENTED = 3, MARTELLO_SCHEME_RESTITUTION = 4 };
enum { MARTELLO_LAW_LINEAR = 1, MARTELLO_LAW_HERTZ = 2, MARTELLO_LAW_KELVIN = 3,
       MARTELLO_LAW_HUNT_CROSSLEY = 4, MARTELLO_LAW_LANKARANI_NIKRAVESH = 5,
       MARTELLO_LAW_FLORES = 6, MARTELLO_LAW_GONTHIER = 7, MARTELLO_LAW_HERTZDAMP = 8,
       MARTELLO_LAW_JANKOWSKI = 9 };
enum { MARTELLO_NPAR_CONTACT = 8, MARTELLO_P_STIFF = 0, MARTELLO_P_EXPONENT = 1,
       MARTELLO_P_DAMPING = 2, MARTELLO_P_RESTITUTION = 3, MARTELLO_P_CLIP = 4,
       MARTELLO_P_MSTAR = 5 };
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
int martello_constant(const char *name, int *value);

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
int martello_model_set_gravity(martello_model *model, double g);
/* A time function: kind MARTELLO_TF_*, par[MARTELLO_NPAR_TF], and for a table n_table
 * samples (t[i], y[i]) with t strictly increasing (y scaled by par[0]). */
int martello_model_add_nodal_force(martello_model *model, int node, int kind,
                                   const double *par, int n_table, const double *t,
                                   const double *y);
int martello_model_set_ground_acceleration(martello_model *model, int kind,
                                           const double *par, int n_table, const double *t,
                                           const double *y);
int martello_model_message(const martello_model *model, char *buf, int buflen);

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
/* Lifecycle: martello_run_create -> martello_run_set_integrator (-> _set_outputs)
 * -> martello_dynamic_run(model, run) -> martello_run_* getters -> martello_run_free.
 * A failed run (status < 0: diverged, unstable, Newton not converged ...) keeps what it
 * computed up to the failure for diagnosis; martello_run_message() says where and why. */
typedef struct martello_run martello_run;

enum { MARTELLO_INT_NEWMARK = 1, MARTELLO_INT_HHT = 2, MARTELLO_INT_GENERALIZED_ALPHA = 3,
       MARTELLO_INT_CENTRAL_DIFFERENCE = 4, MARTELLO_INT_MOREAU_JEAN = 5,
       MARTELLO_INT_NEWMARK_LAGRANGE = 6, MARTELLO_INT_RKF45 = 7, MARTELLO_INT_RK8PD = 8,
       MARTELLO_INT_MSBDF = 9, MARTELLO_INT_IDA = 10 };
/* Slots of the integrator parameter array (0-based). */
enum { MARTELLO_NPAR_INTEGRATOR = 17, MARTELLO_R_DT = 0, MARTELLO_R_T_END = 1,
       MARTELLO_R_BETA = 2, MARTELLO_R_GAMMA = 3, MARTELLO_R_ALPHA = 4, MARTELLO_R_RHO_INF = 5,
       MARTELLO_R_TOL_RESIDUAL = 6, MARTELLO_R_TOL_INCREMENT = 7, MARTELLO_R_MAX_NEWTON = 8,
       MARTELLO_R_CHECK_STABILITY = 9, MARTELLO_R_EVERY = 10, MARTELLO_R_DIVERGENCE_FACTOR = 11,
       MARTELLO_R_RTOL = 12, MARTELLO_R_ATOL = 13, MARTELLO_R_THETA = 14, MARTELLO_R_EVENT_TOL = 15,
       MARTELLO_R_H_MAX = 16 };
enum { MARTELLO_NCOUNTERS = 9, MARTELLO_NENERGY = 9, MARTELLO_NEVENT = 6 };

int martello_run_create(martello_run **run);
void martello_run_free(martello_run **run);
int martello_run_set_integrator(martello_run *run, int kind,
                                const double par[MARTELLO_NPAR_INTEGRATOR]);
int martello_run_set_outputs(martello_run *run, int n_nodes, const int *nodes, int n_contacts,
                             const int *contacts);
/* Links whose force and elongation the history records (0-based; default none). */
int martello_run_set_link_outputs(martello_run *run, int n_links, const int *links);
int martello_dynamic_run(martello_model *model, martello_run *run);
int martello_run_message(const martello_run *run, char *buf, int buflen);
/* History: rows records of cols values, record after record: t, then u, v, a of each output
 * node (all u first, then all v, then all a), then penetration and force of each output
 * contact, then force and elongation of each output link (NaN where an integrator does not
 * report links), then the MARTELLO_NENERGY energy terms. */
int martello_run_history_shape(const martello_run *run, int *rows, int *cols);
int martello_run_history(const martello_run *run, double *buf);
/* Contact phases: n on return; with non-NULL arrays also contact[n] and
 * values[n][6] = {t_on, t_off (-1: open at the end), v_in, v_out, max penetration, max force}. */
int martello_run_events(const martello_run *run, int *n, int *contacts, double *values);
/* counters = {steps, rejected steps, Newton iterations, residual evaluations,
 * factorizations, events, Jacobian evaluations, root-function evaluations, contact
 * chatter resolutions (steps where a contact was held open, see docs/integrators.md)} */
int martello_run_counters(const martello_run *run, long long counters[MARTELLO_NCOUNTERS]);
/* Per node: extremes over the steps, and the largest local maximum of u interpolated between
 * steps (u_peak at t_peak; t_peak = -1 if u never turned back); per contact: max
 * penetration, max force and the number of contact phases. */
int martello_run_peaks(const martello_run *run, double *u_max, double *u_min, double *v_absmax,
                       double *a_absmax, double *pen_max, double *force_max, int *impacts,
                       double *u_peak, double *t_peak);
/* energy = {kinetic, recoverable, input work, damping, plastic, contact dissipation, balance,
 * initial, impact}; extra = {max |balance|, omega_max, dt_crit (explicit), time reached} */
int martello_run_energy(const martello_run *run, double energy[MARTELLO_NENERGY], double extra[4]);
/* Per link: max |force| and max |elongation| over the run (NaN if the integrator does not
 * report link states). */
int martello_run_link_peaks(const martello_run *run, double *force_absmax, double *elongation_absmax);

#ifdef __cplusplus
}
#endif
#endif /* MARTELLO_H */
