!> Checks every time integrator makes: the settings and the scene before a run, divergence
!> (NaN, or mechanical energy far beyond what was put in) during it. One wording for all.
module martello_run_checks
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, scheme_name
   use martello_integrator_settings, only: integrator_settings_t, integrator_name, scheme_supported, INT_LAST
   use martello_results, only: results_t
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: check_run_settings, check_schemes, check_divergence

contains

   !> Every contact's scheme runnable by the integrator; every node set (the settings were
   !> validated by settings_check). stat /= MARTELLO_OK with r%message saying which.
   subroutine check_run_settings(m, s, r, stat)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat
      call check_schemes(m, s%kind, r%message, stat)
      if (stat /= MARTELLO_OK) return
      if (any(m%mass < 0.0_dp)) then
         stat = MARTELLO_ERR_STATE; r%message = 'every node must be set before a run'
      end if
   end subroutine check_run_settings

   !> Every contact's scheme must run on the integrator kind; the message names the
   !> integrators that would (the compatibility table of martello_integrator_settings).
   subroutine check_schemes(m, kind, message, stat)
      type(model_t), intent(in) :: m
      integer, intent(in) :: kind
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      integer :: j, k
      character(len=16) :: num
      character(len=256) :: works
      stat = MARTELLO_OK
      do j = 1, m%ncontact
         if (scheme_supported(kind, m%con_scheme(j))) cycle
         works = ''
         do k = 1, INT_LAST
            if (scheme_supported(k, m%con_scheme(j))) works = trim(works)//' '//integrator_name(k)
         end do
         write (num, '(i0)') j - 1
         stat = MARTELLO_ERR_UNSUPPORTED
         message = 'contact '//trim(num)//': scheme '//scheme_name(m%con_scheme(j))// &
            ' cannot run on '//integrator_name(kind)//'; integrators that can:'//trim(works)
         if (len_trim(works) == 0) message = 'contact '//trim(num)//': scheme '// &
            scheme_name(m%con_scheme(j))//' is static only; use analysis type static'
         return
      end do
   end subroutine check_schemes

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
