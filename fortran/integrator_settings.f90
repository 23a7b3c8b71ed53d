!> Integrator kinds, their settings, and which contact schemes each can run (the
!> compatibility table of docs/integrators.md; martello/scene.py holds the same table for
!> scene-file errors, tests/test_compatibility.py checks that the two agree).
module martello_integrator_settings
   use martello_kinds, only: dp
   use martello_model, only: SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, SCHEME_RESTITUTION
   implicit none
   private
   public :: integrator_settings_t, integrator_name, scheme_supported, &
      INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA, INT_CENTRAL_DIFFERENCE, INT_MOREAU_JEAN, &
      INT_NEWMARK_LAGRANGE, INT_RKF45, INT_RK8PD, INT_MSBDF, INT_IDA, INT_LAST, &
      NPAR_INTEGRATOR, R_DT, R_T_END, R_BETA, R_GAMMA, R_ALPHA, R_RHO_INF, R_TOL_RESIDUAL, &
      R_TOL_INCREMENT, R_MAX_NEWTON, R_CHECK_STABILITY, R_EVERY, R_DIVERGENCE_FACTOR, R_RTOL, &
      R_ATOL, R_THETA, R_EVENT_TOL, R_H_MAX

   integer, parameter :: INT_NEWMARK = 1, INT_HHT = 2, INT_GENERALIZED_ALPHA = 3, &
                         INT_CENTRAL_DIFFERENCE = 4, INT_MOREAU_JEAN = 5, &
                         INT_NEWMARK_LAGRANGE = 6, INT_RKF45 = 7, INT_RK8PD = 8, INT_MSBDF = 9, &
                         INT_IDA = 10, INT_LAST = 10

   !> Slots of the integrator parameter array of martello_run_set_integrator (0-based in C).
   integer, parameter :: NPAR_INTEGRATOR = 17
   integer, parameter :: R_DT = 1, R_T_END = 2, R_BETA = 3, R_GAMMA = 4, R_ALPHA = 5, &
                         R_RHO_INF = 6, R_TOL_RESIDUAL = 7, R_TOL_INCREMENT = 8, &
                         R_MAX_NEWTON = 9, R_CHECK_STABILITY = 10, R_EVERY = 11, &
                         R_DIVERGENCE_FACTOR = 12, R_RTOL = 13, R_ATOL = 14, R_THETA = 15, &
                         R_EVENT_TOL = 16, R_H_MAX = 17

   type :: integrator_settings_t
      integer :: kind = INT_NEWMARK
      real(dp) :: dt = 0.0_dp, t_end = 0.0_dp       !< fixed step, or output interval (adaptive)
      real(dp) :: beta = 0.25_dp, gamma = 0.5_dp     !< Newmark
      real(dp) :: alpha = 0.0_dp                     !< HHT, in [−1/3, 0]
      real(dp) :: rho_inf = 1.0_dp                   !< generalized-α, in [0, 1]
      real(dp) :: tol_residual = 1.0e-9_dp           !< ‖r‖∞ ≤ tol·force scale
      real(dp) :: tol_increment = 1.0e-11_dp         !< predicted ‖Δu‖∞ ≤ tol·displacement scale
      integer :: max_newton = 30
      logical :: check_stability = .true.           !< central difference: refuse Δt > Δt_crit
      integer :: every = 1                           !< record every n-th step (fixed step)
      real(dp) :: divergence_factor = 10.0_dp        !< mechanical energy > factor·(E0 + input)
      real(dp) :: rtol = 1.0e-8_dp, atol = 1.0e-12_dp  !< adaptive steppers (GSL, IDA)
      real(dp) :: theta = 0.5_dp                     !< Moreau–Jean θ
      real(dp) :: event_tol = 1.0e-12_dp             !< event location, absolute in time [s]
      real(dp) :: h_max = 0.0_dp                     !< adaptive: largest step (0: no limit)
   end type integrator_settings_t

contains

   pure function integrator_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      select case (kind)
      case (INT_NEWMARK); name = 'newmark'
      case (INT_HHT); name = 'hht'
      case (INT_GENERALIZED_ALPHA); name = 'generalized-alpha'
      case (INT_CENTRAL_DIFFERENCE); name = 'central-difference'
      case (INT_MOREAU_JEAN); name = 'moreau-jean'
      case (INT_NEWMARK_LAGRANGE); name = 'newmark-lagrange'
      case (INT_RKF45); name = 'rkf45'
      case (INT_RK8PD); name = 'rk8pd'
      case (INT_MSBDF); name = 'msbdf'
      case (INT_IDA); name = 'ida'
      case default; name = 'unknown'
      end select
   end function integrator_name

   !> The compatibility table. Penalty contacts are smooth forces (every integrator but the
   !> seed's Newmark–Lagrange, which is built for rigid impacts); Lagrange and restitution
   !> contacts need event location or impulse-level time stepping.
   pure logical function scheme_supported(kind, scheme) result(ok)
      integer, intent(in) :: kind, scheme
      select case (scheme)
      case (SCHEME_PENALTY)
         ok = kind /= INT_NEWMARK_LAGRANGE
      case (SCHEME_LAGRANGE, SCHEME_RESTITUTION)
         ok = kind >= INT_MOREAU_JEAN
      case default   ! augmented Lagrange is a static scheme
         ok = .false.
      end select
      if (scheme == SCHEME_AUGMENTED) ok = .false.
   end function scheme_supported
end module martello_integrator_settings
