!> Status codes returned through the C door: 0 success, > 0 a result with a non-error
!> outcome, < 0 failure. Their names and meanings are the registry's table "status"
!> (fortran/registry.f90); tests/test_registry.py checks the enum of c/martello.h against it.
module martello_status
   implicit none
   private
   public :: MARTELLO_OK, MARTELLO_ILL_CONDITIONED, MARTELLO_ROOT_FOUND, &
      MARTELLO_ERR_ARGUMENT, MARTELLO_ERR_MEMORY, MARTELLO_ERR_SINGULAR, &
      MARTELLO_ERR_NOT_CONVERGED, MARTELLO_ERR_DIVERGED, MARTELLO_ERR_UNSUPPORTED, &
      MARTELLO_ERR_UNSTABLE, MARTELLO_ERR_LAPACK, MARTELLO_ERR_STEP_UNDERFLOW, &
      MARTELLO_ERR_EXTERNAL, MARTELLO_ERR_STATE, MARTELLO_ERR_LIMIT, MARTELLO_ERR_INTERRUPTED

   integer, parameter :: MARTELLO_OK = 0
   integer, parameter :: MARTELLO_ILL_CONDITIONED = 1  !< solved, but digits were lost
   integer, parameter :: MARTELLO_ROOT_FOUND = 2       !< an event stopped the integration
   integer, parameter :: MARTELLO_ERR_ARGUMENT = -1
   integer, parameter :: MARTELLO_ERR_MEMORY = -2
   integer, parameter :: MARTELLO_ERR_SINGULAR = -3
   integer, parameter :: MARTELLO_ERR_NOT_CONVERGED = -4
   integer, parameter :: MARTELLO_ERR_DIVERGED = -5
   integer, parameter :: MARTELLO_ERR_UNSUPPORTED = -6
   integer, parameter :: MARTELLO_ERR_UNSTABLE = -7
   integer, parameter :: MARTELLO_ERR_LAPACK = -8
   integer, parameter :: MARTELLO_ERR_STEP_UNDERFLOW = -9
   integer, parameter :: MARTELLO_ERR_EXTERNAL = -10   !< GSL or SUNDIALS reported a failure
   integer, parameter :: MARTELLO_ERR_STATE = -11      !< call out of order (e.g. run before build)
   integer, parameter :: MARTELLO_ERR_LIMIT = -12      !< max_steps or max_wall reached
   integer, parameter :: MARTELLO_ERR_INTERRUPTED = -13 !< the caller's progress callback stopped it
end module martello_status
