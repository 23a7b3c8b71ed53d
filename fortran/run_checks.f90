!> Checks every time integrator makes: the settings and the scene before a run, divergence
!> (NaN, or mechanical energy far beyond what was put in) during it. One wording for all.
module martello_run_checks
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, scheme_name
   use martello_integrator_settings, only: integrator_settings_t, integrator_name, scheme_supported
   use martello_results, only: results_t
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: check_run_settings, check_divergence

contains

   !> dt, t_end and every positive; every contact's scheme runnable by the integrator; every
   !> node set. stat /= MARTELLO_OK with r%message saying which.
   subroutine check_run_settings(m, s, r, stat)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat
      integer :: j
      character(len=16) :: num
      stat = MARTELLO_OK
      if (.not. (s%dt > 0.0_dp .and. s%t_end > 0.0_dp .and. s%every >= 1)) then
         stat = MARTELLO_ERR_ARGUMENT
         r%message = 'dynamic run: need dt > 0, t_end > 0 and every >= 1'
         return
      end if
      do j = 1, m%ncontact
         if (.not. scheme_supported(s%kind, m%con_scheme(j))) then
            write (num, '(i0)') j - 1
            stat = MARTELLO_ERR_UNSUPPORTED
            r%message = 'contact '//trim(num)//': scheme '//scheme_name(m%con_scheme(j))// &
               ' cannot run on '//integrator_name(s%kind)//' (see docs/integrators.md)'
            return
         end if
      end do
      if (any(m%mass < 0.0_dp)) then
         stat = MARTELLO_ERR_STATE; r%message = 'every node must be set before a run'
      end if
   end subroutine check_run_settings

   !> Divergence at time t: a non-finite state, or e_mech > divergence_factor·(e0 + Σ|ΔW|).
   !> advice ends the message (what to change).
   subroutine check_divergence(s, t, e_mech, e0, w_abs, u, v, advice, r, stat)
      type(integrator_settings_t), intent(in) :: s
      real(dp), intent(in) :: t, e_mech, e0, w_abs, u(:), v(:)
      character(len=*), intent(in) :: advice
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (.not. (ieee_is_finite(e_mech) .and. all(ieee_is_finite(u)) .and. all(ieee_is_finite(v)))) then
         write (r%message, '(a,a,es12.5,a)') integrator_name(s%kind), ' diverged at t = ', t, &
            ' s: non-finite state (NaN/inf)'
         stat = MARTELLO_ERR_DIVERGED; r%t_end_reached = t
      else if (e_mech > s%divergence_factor*(e0 + w_abs) + tiny(1.0_dp) .and. e0 + w_abs > 0.0_dp) then
         write (r%message, '(a,a,es12.5,a,es10.3,a,es10.3,a,a)') integrator_name(s%kind), &
            ' diverged at t = ', t, ' s: mechanical energy ', e_mech, ' J exceeds ', &
            s%divergence_factor*(e0 + w_abs), ' J (divergence_factor x (initial energy + input work)); ', advice
         stat = MARTELLO_ERR_DIVERGED; r%t_end_reached = t
      end if
   end subroutine check_divergence
end module martello_run_checks
