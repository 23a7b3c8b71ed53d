!> The seed's Newmark–Lagrange scheme (placeholder until the Nonsmooth issue lands it).
module martello_newmark_lagrange
   use martello_status, only: MARTELLO_ERR_UNSUPPORTED
   use martello_model, only: model_t
   use martello_integrator_settings, only: integrator_settings_t
   use martello_results, only: results_t
   implicit none
   private
   public :: run_newmark_lagrange
contains
   subroutine run_newmark_lagrange(m, s, r, stat)
      type(model_t), intent(inout) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat
      stat = MARTELLO_ERR_UNSUPPORTED
      r%message = 'newmark-lagrange is not built yet'
      if (.false.) print *, m%n, s%dt
   end subroutine run_newmark_lagrange
end module martello_newmark_lagrange
