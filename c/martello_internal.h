/* The door between the Fortran kernels and the C integrators (GSL, SUNDIALS): force
 * evaluation of a scene and the recording of results. Not part of the public API.
 * Node arrays have length n (0-based nodes), contact arrays length n_contacts. */
#ifndef MARTELLO_INTERNAL_H
#define MARTELLO_INTERNAL_H
#include "martello.h"

typedef struct martello_eval martello_eval;

/* Scene topology for impact laws. con_a/con_b are 0-based nodes, -1 = ground; fixed[i] is 0/1;
 * restitution[j] is the contact's e (or -1 if none given). Pass NULL for what you don't need. */
int martello_model_topology(const martello_model *model, int *n, int *n_contacts, double *mass,
                            int *fixed, int *con_a, int *con_b, int *scheme, double *gap,
                            double *restitution, int *n_couplings);

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
/* The force of every penalty contact at the last evaluation (0 for other schemes). */
int martello_eval_contact_forces(martello_eval *ev, double *force);
/* x <- M^-1 x on the free nodes (0 on fixed ones). */
int martello_eval_solve_mass(martello_eval *ev, double *x);
int martello_eval_contacts(martello_eval *ev, const double *u, const double *v, double *pen,
                           double *rate);
/* Accept (u, v) at the end of a step: path-dependent links (hysteresis) commit. */
int martello_eval_commit(martello_eval *ev, const double *u, const double *v);
int martello_eval_energy(martello_eval *ev, const double *u, const double *v, double *kinetic,
                         double *recoverable);

/* The run being filled; its settings, as martello_run_set_settings validated them. */
int martello_run_settings(const martello_run *run, martello_settings *settings);
int martello_run_track(martello_run *run, double t, const double *u, const double *v,
                       const double *a, const double *pen, const double *force);
int martello_run_record(martello_run *run, double t, const double *u, const double *v,
                        const double *a, const double *pen, const double *force,
                        const double energy[MARTELLO_NENERGY]);
int martello_run_add_event(martello_run *run, int contact, const double values[MARTELLO_NEVENT]);
int martello_run_add_counts(martello_run *run, const long long inc[MARTELLO_NCOUNTERS]);
int martello_run_set_message(martello_run *run, const char *message);
/* energy: the final energy terms; balance_max: max |balance| seen; t_reached: where it stopped */
int martello_run_finish(martello_run *run, double t_reached,
                        const double energy[MARTELLO_NENERGY], double balance_max);

/* The C integrators, dispatched by martello_dynamic_run. */
int martello_event_driven_run(martello_model *model, martello_run *run);
int martello_ida_run(martello_model *model, martello_run *run);
#endif
