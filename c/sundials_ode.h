/* The first-order ODE of a scene on SUNDIALS CVODE and ARKODE (c/sundials_ode.c): the problem
 * and the pieces of its run that c/local_stepping.c drives once per cluster (docs/sundials-ode.md,
 * local stepping). Not part of the public API. */
#ifndef MARTELLO_SUNDIALS_ODE_H
#define MARTELLO_SUNDIALS_ODE_H
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include "ode_events.h"

#pragma GCC visibility push(hidden)

typedef struct {
  ode_events E;            /* contacts, events, the observer's hand-overs (c/ode_events.c) */
  int ark;                 /* 0: CVODE, 1: ARKODE */
  void *ida;               /* IDA on this problem's events when the integrator is IDA (c/ida.c) */
  int kind;                /* KIND_* */
  int erk_id, dirk_id;     /* ARKODE tables (ARKODE_*_NONE when absent) */
  const char *name;        /* "CVODE" or "ARKODE": what the messages say */
  int kd, lumped;
  sunindextype N;
  double *kb, *cb;         /* the tangents' bands (martello_eval_tangent) */
  void *mem;
  char msg[240];
  /* ARKODE's rows by a step of their own (c/sundials_ode.c row_by_step): where the table's order
   * exceeds the interpolant's degree, a row inside a step is one step of the same table from the
   * step's start, on a second ARKODE memory (created at the first such row) */
  int rows_by_step;
  SUNContext ctx;
  void *row_mem;
  SUNMatrix row_J;
  SUNLinearSolver row_LS;
  N_Vector y_start, y_int;  /* the state at the start of the last step; at its end */
  N_Vector y_row;           /* a row's state */
  double t_start, t_int;
  long nst_seen;            /* the main memory's steps when t_int was read */
  long row_rhs;             /* right-hand sides of the row steps (in the run's counts) */
} ode_problem;

/* The problem of model with the settings and observer of run (P zeroed); its arrays freed and
 * its integrator with them. */
int ode_problem_setup(ode_problem *P, martello_model *model, martello_run *run);
void ode_problem_release(ode_problem *P);
/* The integrator at (0, y) with its linear solver and roots; a restart at (t, y); the state y at
 * a restart at t made consistent (the events of E->act). */
int ode_problem_create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *J, SUNLinearSolver *LS);
int ode_problem_restart(ode_problem *P, double t, N_Vector y);
int ode_problem_prepare_restart(ode_problem *P, double t, double *y);
/* The integrator's counters since the last call, to the run. */
int ode_problem_flush_counts(ode_problem *P);
/* The state y at t (committed) as a sample of the observer (row = 1: an output row on the
 * interpolant, off the energy grid); k its output grid point or -1. */
int ode_problem_observe(ode_problem *P, double t, const double *y, int k, int row);
/* MARTELLO_OK for a SUNDIALS flag >= 0, else the run fails naming call. */
int ode_problem_check(ode_problem *P, int flag, const char *call);
/* A reported root exactly 0 at the return: 1 (restart with no event). */
int ode_problem_root_stays_zero(ode_problem *P, const double *y, const int *found);
/* The k-th derivative of the last step's interpolant at t. */
int ode_problem_interpolant(ode_problem *P, double t, int k, N_Vector out);
double ode_problem_last_step(ode_problem *P);
/* One step towards tout (CV_ONE_STEP, ARK_ONE_STEP): the integrator's flag if < 0, else one of */
enum { ODE_STEP_DONE, ODE_STEP_ROOT, ODE_STEP_TSTOP };
int ode_problem_step(ode_problem *P, double tout, N_Vector y, double *tret);
/* The roots found at the last return; the stop time; the time the integrator reached (t_last if
 * it cannot say); a flag's name. */
int ode_problem_root_info(ode_problem *P, int *found);
int ode_problem_stop(ode_problem *P, double t);
double ode_problem_current_time(ode_problem *P, double t_last);
const char *ode_problem_flag(ode_problem *P, int flag);

/* The same pieces on IDA (c/ida.c; docs/ida.md): the wrappers above choose them when P->ida. */
int ida_seam_setup(ode_problem *P, martello_model *model, martello_run *run);
void ida_seam_release(ode_problem *P);
int ida_seam_create(ode_problem *P, SUNContext ctx, N_Vector y, SUNMatrix *J, SUNLinearSolver *LS);
int ida_seam_restart(ode_problem *P, double t, N_Vector y);
int ida_seam_prepare_restart(ode_problem *P, double t, double *y);
int ida_seam_flush_counts(ode_problem *P);
int ida_seam_check(ode_problem *P, int flag, const char *call);
int ida_seam_root_stays_zero(ode_problem *P, const double *y, const int *found);
int ida_seam_interpolant(ode_problem *P, double t, int k, N_Vector out);
double ida_seam_last_step(ode_problem *P);
int ida_seam_step(ode_problem *P, double tout, N_Vector y, double *tret);
int ida_seam_root_info(ode_problem *P, int *found);
int ida_seam_stop(ode_problem *P, double t);
double ida_seam_current_time(ode_problem *P, double t_last);
const char *ida_seam_flag(ode_problem *P, int flag);
#pragma GCC visibility pop
#endif
