!> Explicit central difference (velocity Verlet) as a stepper of the fixed-step strategy
!> (docs/integrators.md "central difference"), with an extrapolated damping velocity
!> v_n + h a_n and an a priori stability check against Δt_crit = 2/ω_max.
module martello_central_difference
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth
   use martello_band_matrix, only: band_t, band_init
   use martello_assembly, only: internal_forces, external_forces, mech_commit, external_work
   use martello_observer, only: observer_t, observer_work, observer_fail
   use martello_run_quantities, only: C_RESIDUALS, C_FACTORIZATIONS
   use martello_integrator_settings, only: integrator_settings_t
   use martello_stability, only: omega_max
   use martello_fixed_step, only: stepper_t, stepper_rest_start, solve_free_mass, stepper_fail, &
      contact_state
   implicit none
   private
   public :: central_difference_t

   type, extends(stepper_t) :: central_difference_t
      real(dp), allocatable :: fint(:), fext(:), fext_n(:), work(:)
      type(band_t) :: mband
   contains
      procedure :: init
      procedure :: step
   end type central_difference_t

contains

   !> The state at t = 0, and the stability of the scheme before anything is written.
   subroutine init(self, m, s, o, stat)
      class(central_difference_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, info
      character(len=512) :: msg
      n = m%n
      allocate (self%fint(0:n), self%fext(0:n), self%fext_n(0:n), self%work(0:n), stat=stat)
      if (stat /= 0) call out_of_memory('the force vectors of central difference', &
                                        REAL_BYTES*4*(n + 1.0_dp), FIX_SMALLER_SCENE, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%mband, n, model_bandwidth(m), stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      call stepper_rest_start(self, m, s, self%mband, self%fint, self%fext, o, stat)
      if (stat /= MARTELLO_OK) return
      self%advice = 'the step is past the stability limit'
      ! Velocity Verlet conserves ½vᵀMv − (h²/8)aᵀMa exactly against trapezoidal work
      self%ke_aMa = 0.125_dp*self%h*self%h

      call omega_max(m, o%omega_max, info, stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      if (info /= 0 .and. s%check_stability) then
         write (msg, '(a,i0,a)') 'central difference: the stability limit could not be computed'// &
            ' (LAPACK dsbgvx info = ', info, '): the mass matrix is not positive definite'
         call observer_fail(o, MARTELLO_ERR_SINGULAR, 0.0_dp, msg, stat)
         return
      end if
      if (info == 0 .and. o%omega_max > 0.0_dp) o%dt_critical = 2.0_dp/o%omega_max
      if (s%check_stability .and. o%dt_critical > 0.0_dp .and. self%h > o%dt_critical) then
         write (msg, '(a,a,a,a,a,a,a)') 'central difference is unstable: dt = ', &
            sci(self%h, 5), ' s exceeds dt_crit = 2/omega_max = ', sci(o%dt_critical, 5), &
            ' s (omega_max = ', sci(o%omega_max, 4), ' rad/s, penalty stiffness included); reduce dt or use an implicit integrator'
         call observer_fail(o, MARTELLO_ERR_UNSTABLE, 0.0_dp, msg, stat)
         return
      end if
   end subroutine init

   !> Velocity Verlet. Velocity-dependent forces (dampers, contact rates) see the explicit
   !> estimate v* = v_n + h a_n of v_{n+1}: O(h²) accurate, so the scheme stays second
   !> order with damping (a lagged v_{n+1/2} would make it first order).
   subroutine step(self, m, t, o, stat)
      class(central_difference_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      real(dp) :: h, wd, wl, wc
      logical :: ok
      stat = MARTELLO_OK
      h = self%h
      associate (u => self%u, v => self%v, a => self%a, un => self%un, vn => self%vn, &
                 an => self%an, work => self%work, fext => self%fext, fixed_nodes => self%fixed_nodes)
         self%fext_n = fext
         call external_forces(m, self%mrow, t, fext)
         u = un + h*(vn + 0.5_dp*h*an)
         work = vn + h*an
         u(fixed_nodes) = un(fixed_nodes); work(fixed_nodes) = 0.0_dp
         call internal_forces(m, self%ms, u, work, self%fint)
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         a = fext - self%fint
         call solve_free_mass(m, fixed_nodes, self%mband, a, ok)
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         if (.not. ok) then
            call stepper_fail(o, MARTELLO_ERR_SINGULAR, t, 'the mass matrix is singular on the free nodes', stat)
            return
         end if
         v = vn + 0.5_dp*h*(an + a)
         v(fixed_nodes) = 0.0_dp
         ! energy balance: trapezoidal work of every force over the step (elements in commit)
         call mech_commit(m, self%ms, u, wd, wl, wc)
         call observer_work(o, damping=wd, links=wl, contact=wc)
         call observer_work(o, external=external_work(m, self%fext_n, fext, un, u))
         call contact_state(self, m)
      end associate
   end subroutine step
end module martello_central_difference
