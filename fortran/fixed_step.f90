!> The fixed-step strategy (docs/run-layer.md): one time loop for every one-step method of
!> martello_stepper — steps t_k = k·h, k = 1 … n until t_end is reached (the last t_k ≥
!> t_end is reported as t_reached, never a shortened step labelled t_end), the phases of
!> the penalty contacts located on the free side of each step, and one observer sample per
!> accepted step. A failed step stops the run with the stepper's message.
module martello_fixed_step
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_integrator_settings, only: integrator_settings_t
   use martello_run_checks, only: check_run_settings
   use martello_observer, only: observer_t, observer_begin, observer_sample, &
      observer_open_phase, observer_penalty_phases, observer_finish, C_STEPS
   use martello_stepper, only: stepper_t
   implicit none
   private
   public :: run_fixed_step

   !> Samples between energy evaluations (kinetic and recoverable energy are two passes over
   !> the model, as dear as a cheap step): a NaN is caught at once through the works.
   integer, parameter :: ENERGY_CHECK = 16

contains

   !> Run the scene from t = 0 to t_end with the stepper stp. stat < 0 on failure, with
   !> o%message saying where and why (the results so far stay in o for diagnosis).
   subroutine run_fixed_step(m, s, o, stp, stat)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      class(stepper_t), intent(inout) :: stp
      integer, intent(out) :: stat
      integer :: k, c
      real(dp) :: t

      call check_run_settings(m, s, o%message, stat)
      if (stat /= MARTELLO_OK) return
      call stp%init(m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      call observer_begin(o, m, stp%ms, stp%u, stp%v, stp%a, ENERGY_CHECK, stp%advice, stp%ke_aMa)
      ! contacts already closed at t = 0 start a contact phase there (no approach to locate)
      do c = 1, m%ncontact
         if (stp%ms%con_on(c)) &
            call observer_open_phase(o, c, 0.0_dp, stp%v(m%con_a(c)) - stp%v(m%con_b(c)))
      end do
      t = 0.0_dp
      call sample(0)
      if (stat /= MARTELLO_OK) return

      do k = 1, o%n_grid
         stp%un = stp%u; stp%vn = stp%v; stp%an = stp%a; stp%t0 = t
         t = k*stp%h
         call stp%step(m, t, o, stat)
         if (stat /= MARTELLO_OK) return
         o%counters(C_STEPS) = o%counters(C_STEPS) + 1_i8
         call observer_penalty_phases(o, m, stp%ms, stp%un, stp%vn, stp%an, stp%u, stp%v, stp%a, &
                                      t, stp%h)
         call sample(k)
         if (stat /= MARTELLO_OK) return
      end do
      call observer_finish(o, t)

   contains

      !> The state at t_k; the previous one is the stepper's own (un, vn, an): no copy.
      subroutine sample(kk)
         integer, intent(in) :: kk
         call observer_sample(o, m, stp%ms, t, stp%u, stp%v, stp%a, stp%pen, stp%force, kk, stat, &
                              stp%ms%link_f, stp%ms%link_u, stp%un(1:), stp%vn(1:), stp%an(1:))
      end subroutine sample
   end subroutine run_fixed_step
end module martello_fixed_step
