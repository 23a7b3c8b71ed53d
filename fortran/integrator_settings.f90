!> The settings of a dynamic run: integrator_settings_t, interoperable field by field with
!> martello_settings of c/martello.h (tests/test_registry.py checks the layout), its defaults
!> and valid ranges (the registry's table "settings"), and settings_check, the one validation
!> of a run's settings (martello_run_set_settings). The integrator names and the scheme ×
!> integrator compatibility are the registry's too (docs/integrators.md).
module martello_integrator_settings
   use, intrinsic :: iso_c_binding, only: c_int, c_double, c_bool
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, MARTELLO_ERR_ARGUMENT, sci
   use martello_registry, only: INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA, &
      INT_CENTRAL_DIFFERENCE, INT_MOREAU_JEAN, INT_NEWMARK_LAGRANGE, INT_RKF45, INT_RK8PD, &
      INT_MSBDF, INT_IDA, INT_LAST, SETTINGS, INTEGRATORS, setting_t, NSETTINGS, S_DT, S_T_END, &
      S_BETA, S_GAMMA, S_ALPHA, S_RHO_INF, S_TOL_RESIDUAL, S_TOL_INCREMENT, S_MAX_NEWTON, &
      S_CHECK_STABILITY, S_EVERY, S_DIVERGENCE_FACTOR, S_RTOL, S_ATOL, S_THETA, S_EVENT_TOL, &
      S_H_MAX, S_FUSED_CHAIN, S_MAX_STEPS, S_MAX_WALL, S_EVENT_SPLIT, S_METHOD, S_MODAL_VECTORS, S_LOCAL_STEPPING, T_INT, &
      METHODS, &
      INT_CVODE, INT_ARKODE
   implicit none
   private
   public :: integrator_settings_t, integrator_name, scheme_supported, settings_default, &
      settings_check, INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA, INT_CENTRAL_DIFFERENCE, &
      INT_MOREAU_JEAN, INT_NEWMARK_LAGRANGE, INT_RKF45, INT_RK8PD, INT_MSBDF, INT_IDA, INT_CVODE, &
      INT_ARKODE, INT_LAST

   !> martello_settings. Defaults are the registry's; which fields an integrator reads is its
   !> row of the registry's table "reads".
   type, bind(C) :: integrator_settings_t
      integer(c_int) :: kind = INT_NEWMARK                               !< INT_*
      real(c_double) :: dt = SETTINGS(S_DT)%default        !< fixed step, or output interval (adaptive)
      real(c_double) :: t_end = SETTINGS(S_T_END)%default
      real(c_double) :: beta = SETTINGS(S_BETA)%default                  !< Newmark
      real(c_double) :: gamma = SETTINGS(S_GAMMA)%default                !< Newmark
      real(c_double) :: alpha = SETTINGS(S_ALPHA)%default                !< HHT
      real(c_double) :: rho_inf = SETTINGS(S_RHO_INF)%default            !< generalized-α
      real(c_double) :: tol_residual = SETTINGS(S_TOL_RESIDUAL)%default  !< ‖r‖∞ ≤ tol·force scale
      real(c_double) :: tol_increment = SETTINGS(S_TOL_INCREMENT)%default !< ‖Δu‖∞ ≤ tol·u scale
      integer(c_int) :: max_newton = nint(SETTINGS(S_MAX_NEWTON)%default)
      !> central difference: refuse Δt > Δt_crit
      logical(c_bool) :: check_stability = SETTINGS(S_CHECK_STABILITY)%default /= 0.0_dp
      integer(c_int) :: every = nint(SETTINGS(S_EVERY)%default)          !< record every n-th step
      !> diverged when the mechanical energy > factor·(E0 + input)
      real(c_double) :: divergence_factor = SETTINGS(S_DIVERGENCE_FACTOR)%default
      real(c_double) :: rtol = SETTINGS(S_RTOL)%default                  !< adaptive steppers
      real(c_double) :: atol = SETTINGS(S_ATOL)%default
      real(c_double) :: theta = SETTINGS(S_THETA)%default                !< Moreau–Jean θ
      real(c_double) :: event_tol = SETTINGS(S_EVENT_TOL)%default        !< absolute in time [s]
      real(c_double) :: h_max = SETTINGS(S_H_MAX)%default                !< 0: no limit
      !> Newmark on a chain: the fused chain step (docs/run-layer.md); false: the general path
      logical(c_bool) :: fused_chain = SETTINGS(S_FUSED_CHAIN)%default /= 0.0_dp
      !> the budget of a run: steps (a whole number) and wall-clock seconds (0: no limit)
      real(c_double) :: max_steps = SETTINGS(S_MAX_STEPS)%default
      real(c_double) :: max_wall = SETTINGS(S_MAX_WALL)%default
      !> the Newmark family: split a step at a located penalty onset/separation (docs/integrators.md)
      logical(c_bool) :: event_split = SETTINGS(S_EVENT_SPLIT)%default /= 0.0_dp
      !> cvode, arkode: the method, a value of the registry's table methods (0: the default)
      integer(c_int) :: method = nint(SETTINGS(S_METHOD)%default)
      !> fast-nonlinear: 0 all modes; m > 0 that many load-dependent Ritz vectors
      integer(c_int) :: modal_vectors = nint(SETTINGS(S_MODAL_VECTORS)%default)
      !> cvode, arkode: integrate cluster by cluster (docs/sundials-ode.md, local stepping)
      logical(c_bool) :: local_stepping = SETTINGS(S_LOCAL_STEPPING)%default /= 0.0_dp
   end type integrator_settings_t

contains

   pure function integrator_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      name = 'unknown'
      if (kind >= 1 .and. kind <= INT_LAST) name = trim(INTEGRATORS(kind)%name)
   end function integrator_name

   !> Whether the integrator runs contacts of the scheme (the registry's table compatibility).
   pure logical function scheme_supported(kind, scheme) result(ok)
      integer, intent(in) :: kind, scheme
      ok = .false.
      if (kind >= 1 .and. kind <= INT_LAST .and. scheme >= 0 .and. scheme < bit_size(scheme)) &
         ok = btest(INTEGRATORS(kind)%schemes, scheme)
   end function scheme_supported

   !> The registry's defaults for integrator kind; stat = MARTELLO_ERR_ARGUMENT if unknown.
   pure subroutine settings_default(kind, s, stat)
      integer, intent(in) :: kind
      type(integrator_settings_t), intent(out) :: s
      integer, intent(out) :: stat
      stat = merge(MARTELLO_OK, MARTELLO_ERR_ARGUMENT, kind >= 1 .and. kind <= INT_LAST)
      s%kind = kind
   end subroutine settings_default

   !> The one validation of a run's settings: a known integrator, and every setting it reads
   !> within the registry's range. The message names the field, its value and what is valid.
   subroutine settings_check(s, message, stat)
      type(integrator_settings_t), intent(in) :: s
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      integer :: i
      character(len=32) :: num
      stat = MARTELLO_ERR_ARGUMENT
      if (s%kind < 1 .or. s%kind > INT_LAST) then
         write (num, '(i0)') s%kind
         message = 'settings.kind = '//trim(num)//' is no integrator: use a MARTELLO_INT_*'// &
            ' value (the registry''s table integrators)'
         return
      end if
      do i = 1, NSETTINGS
         if (.not. btest(INTEGRATORS(s%kind)%reads, i)) cycle
         if (in_range(SETTINGS(i), setting_value(s, i))) cycle
         if (SETTINGS(i)%type == T_INT) then
            write (num, '(i0)') nint(setting_value(s, i))
         else
            num = sci(setting_value(s, i), 4)
         end if
         message = 'settings.'//trim(SETTINGS(i)%name)//' = '//trim(adjustl(num))// &
            ' is invalid for '//integrator_name(s%kind)//': set it to '//trim(SETTINGS(i)%text)
         return
      end do
      if (btest(INTEGRATORS(s%kind)%reads, S_METHOD) .and. s%method /= 0) then
         if (.not. any(METHODS%value == s%method .and. METHODS%integrator == s%kind)) then
            write (num, '(i0)') s%method
            message = 'settings.method = '//trim(num)//' is no method of '// &
               integrator_name(s%kind)//': set it to 0 or to the value of a row of the'// &
               ' registry''s table methods whose integrator is '//integrator_name(s%kind)
            return
         end if
      end if
      if (s%max_steps /= aint(s%max_steps)) then
         num = sci(s%max_steps, 4)
         message = 'settings.max_steps = '//trim(adjustl(num))//' is invalid for '// &
            integrator_name(s%kind)//': set it to '//trim(SETTINGS(S_MAX_STEPS)%text)
         return
      end if
      stat = MARTELLO_OK
   end subroutine settings_check

   ! ---------------------------------------------------------------- private helpers

   pure logical function in_range(st, x)
      type(setting_t), intent(in) :: st
      real(dp), intent(in) :: x
      logical :: lo_ok, hi_ok
      lo_ok = merge(x > st%lo, x >= st%lo, st%lo_open)     ! NaN fails both bounds
      hi_ok = merge(x < st%hi, x <= st%hi, st%hi_open)
      in_range = lo_ok .and. hi_ok
   end function in_range

   !> Setting i (a row of the registry's table settings) of s, as a number.
   pure real(dp) function setting_value(s, i) result(x)
      type(integrator_settings_t), intent(in) :: s
      integer, intent(in) :: i
      select case (i)
      case (S_DT); x = s%dt
      case (S_T_END); x = s%t_end
      case (S_BETA); x = s%beta
      case (S_GAMMA); x = s%gamma
      case (S_ALPHA); x = s%alpha
      case (S_RHO_INF); x = s%rho_inf
      case (S_TOL_RESIDUAL); x = s%tol_residual
      case (S_TOL_INCREMENT); x = s%tol_increment
      case (S_MAX_NEWTON); x = s%max_newton
      case (S_CHECK_STABILITY); x = merge(1.0_dp, 0.0_dp, logical(s%check_stability))
      case (S_EVERY); x = s%every
      case (S_DIVERGENCE_FACTOR); x = s%divergence_factor
      case (S_RTOL); x = s%rtol
      case (S_ATOL); x = s%atol
      case (S_THETA); x = s%theta
      case (S_EVENT_TOL); x = s%event_tol
      case (S_H_MAX); x = s%h_max
      case (S_FUSED_CHAIN); x = merge(1.0_dp, 0.0_dp, logical(s%fused_chain))
      case (S_MAX_STEPS); x = s%max_steps
      case (S_MAX_WALL); x = s%max_wall
      case (S_EVENT_SPLIT); x = merge(1.0_dp, 0.0_dp, logical(s%event_split))
      case (S_METHOD); x = s%method
      case (S_MODAL_VECTORS); x = s%modal_vectors
      case (S_LOCAL_STEPPING); x = merge(1.0_dp, 0.0_dp, logical(s%local_stepping))
      case default; x = 0.0_dp
      end select
   end function setting_value
end module martello_integrator_settings
