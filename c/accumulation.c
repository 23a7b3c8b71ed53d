/* Accumulations of the C integrators (docs/impulse.md §4): the rule of fortran/impulse.f90
 * (martello_impulse_accumulation) per contact, and the persistent phase of a contact it
 * holds. The integrators hold a contact at the impact that decides it (the state projected
 * onto the contact, the rest of the series' energy to E_IMPACT), but the phase starts where
 * the series ends, at the predicted t_inf; a contact released before t_inf (its pressing
 * force turned within the unresolved rest of the series) closes at t_inf, so that phases and
 * impacts stay in order. A t_inf at or after t_end opens no phase: nothing is written after
 * the run. */
#include <stdlib.h>

#include "martello_internal.h"

int martello_accumulation_init(martello_accumulation *acc, int nc, double t_end) {
  acc->nc = nc;
  acc->t_end = t_end;
  acc->t_hold = calloc(nc > 0 ? (size_t)nc : 1, sizeof *acc->t_hold);
  return acc->t_hold ? MARTELLO_OK : MARTELLO_ERR_MEMORY;
}

void martello_accumulation_free(martello_accumulation *acc) {
  free(acc->t_hold);
  acc->t_hold = NULL;
}

int martello_accumulation_decide(martello_accumulation *acc, int j, double e, double s,
                                 double a, double da, double t, double t_res, double d_res,
                                 double v_res, int restarts) {
  double t_inf;
  if (!martello_impulse_accumulation(e, s, a, da, t, t_res, d_res, v_res, restarts, &t_inf))
    return 0;
  acc->t_hold[j] = t_inf;
  return 1;
}

void martello_accumulation_at(martello_accumulation *acc, int j, double t) {
  acc->t_hold[j] = t;
}

int martello_accumulation_hold(martello_accumulation *acc, martello_observer *obs, int j) {
  if (!(acc->t_hold[j] < acc->t_end)) return MARTELLO_OK;
  return martello_observer_set_phase(obs, j, 1, acc->t_hold[j], 0.0);
}

int martello_accumulation_release(martello_accumulation *acc, martello_observer *obs, int j,
                                  double t, double v) {
  return martello_observer_set_phase(obs, j, 0, t > acc->t_hold[j] ? t : acc->t_hold[j], v);
}
