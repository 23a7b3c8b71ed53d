/* DAE integration on SUNDIALS IDA (placeholder until the Nonsmooth issue lands it). */
#include "martello.h"
#include "martello_internal.h"

int martello_ida_run(martello_model *model, martello_run *run) {
  (void)model;
  martello_run_set_message(run, "IDA integration is not built yet");
  return MARTELLO_ERR_UNSUPPORTED;
}
