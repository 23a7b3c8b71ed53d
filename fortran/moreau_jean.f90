!> Moreau–Jean time stepping (placeholder until the Nonsmooth issue lands it).
module martello_moreau_jean
   use martello_status, only: MARTELLO_ERR_UNSUPPORTED
   use martello_model, only: model_t
   use martello_integrator_settings, only: integrator_settings_t
   use martello_results, only: results_t
   implicit none
   private
   public :: run_moreau_jean
contains
   subroutine run_moreau_jean(m, s, r, stat)
      type(model_t), intent(inout) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat
      stat = MARTELLO_ERR_UNSUPPORTED
      r%message = 'moreau-jean is not built yet'
      if (.false.) print *, m%n, s%dt
   end subroutine run_moreau_jean
end module martello_moreau_jean
