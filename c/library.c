/* Library identity: version, status names, and the versions of GSL, SUNDIALS, FFTW and
 * LAPACK actually linked (queried at run time, so a summary records what really ran). */
#include <stdio.h>
#include <gsl/gsl_version.h>
#include <gsl/gsl_errno.h>
#include <sundials/sundials_version.h>
#include <fftw3.h>
#include "martello.h"
#include "martello_version.h"

extern void ilaver_(int *major, int *minor, int *patch);

const char *martello_version(void) { return MARTELLO_VERSION_STRING; }

int martello_library_versions(char *buf, int buflen) {
  char sundials[64] = "?";
  int major = 0, minor = 0, patch = 0;
  if (buf == NULL || buflen < 1) return MARTELLO_ERR_ARGUMENT;
  SUNDIALSGetVersion(sundials, (int)sizeof sundials);
  ilaver_(&major, &minor, &patch);
  snprintf(buf, (size_t)buflen, "gsl %s; sundials %s; %s; lapack %d.%d.%d", gsl_version,
           sundials, fftw_version, major, minor, patch);
  return MARTELLO_OK;
}

const char *martello_status_name(int status) {
  switch (status) {
    case MARTELLO_OK: return "MARTELLO_OK";
    case MARTELLO_ILL_CONDITIONED: return "MARTELLO_ILL_CONDITIONED";
    case MARTELLO_ROOT_FOUND: return "MARTELLO_ROOT_FOUND";
    case MARTELLO_ERR_ARGUMENT: return "MARTELLO_ERR_ARGUMENT";
    case MARTELLO_ERR_MEMORY: return "MARTELLO_ERR_MEMORY";
    case MARTELLO_ERR_SINGULAR: return "MARTELLO_ERR_SINGULAR";
    case MARTELLO_ERR_NOT_CONVERGED: return "MARTELLO_ERR_NOT_CONVERGED";
    case MARTELLO_ERR_DIVERGED: return "MARTELLO_ERR_DIVERGED";
    case MARTELLO_ERR_UNSUPPORTED: return "MARTELLO_ERR_UNSUPPORTED";
    case MARTELLO_ERR_UNSTABLE: return "MARTELLO_ERR_UNSTABLE";
    case MARTELLO_ERR_LAPACK: return "MARTELLO_ERR_LAPACK";
    case MARTELLO_ERR_STEP_UNDERFLOW: return "MARTELLO_ERR_STEP_UNDERFLOW";
    case MARTELLO_ERR_EXTERNAL: return "MARTELLO_ERR_EXTERNAL";
    case MARTELLO_ERR_STATE: return "MARTELLO_ERR_STATE";
    case MARTELLO_ERR_LIMIT: return "MARTELLO_ERR_LIMIT";
    case MARTELLO_ERR_INTERRUPTED: return "MARTELLO_ERR_INTERRUPTED";
    default: return "MARTELLO_UNKNOWN_STATUS";
  }
}

/* GSL's default handler aborts the process; a library must return codes instead
 * (GSL manual, "Error handling"). Runs once when the shared library is loaded. */
__attribute__((constructor)) static void martello_init(void) { gsl_set_error_handler_off(); }
