/* Event-driven integration on GSL odeiv2 (placeholder until the Nonsmooth issue lands it). */
#include "martello.h"
#include "martello_internal.h"

int martello_event_driven_run(martello_model *model, martello_run *run) {
  (void)model;
  martello_run_set_message(run, "event-driven integration (GSL) is not built yet");
  return MARTELLO_ERR_UNSUPPORTED;
}
