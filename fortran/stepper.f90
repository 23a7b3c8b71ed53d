!> One-step methods of the fixed-step strategy (docs/run-layer.md): a stepper owns one step
!> of its method — the state it advances, the solves, the contact problem of its impulses —
!> and reports to the observer what only it knows (work increments, phases of contacts it
!> resolves itself, its cost counters, its failures). The time loop, the output grid, the
!> phases of penalty contacts and everything measured are the strategy's and the
!> observer's (martello_fixed_step, martello_observer).
!>
!> A new fixed-step integrator extends stepper_t with init and step, in one file, plus one
!> row of the integrator registry and one case of run_dynamic's dispatch.
module martello_stepper
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_assembly, only: mech_state_t, mech_init, mass_times, assemble_mass, internal_forces, &
      external_forces, mech_commit
   use martello_band_matrix, only: band_t, band_zero, band_pin, band_solve
   use martello_integrator_settings, only: integrator_settings_t
   use martello_observer, only: observer_t, observer_fail, C_FACTORIZATIONS
   implicit none
   private
   public :: stepper_t, stepper_start, stepper_rest_start, solve_free_mass, stepper_fail

   type, abstract :: stepper_t
      integer :: n = 0, nc = 0
      real(dp) :: h = 0.0_dp
      !> the state at the end of the step (u, v, a) and at its start (un, vn, an, set by the
      !> strategy before each step); node arrays run 0:n, 0 = ground (always at rest)
      real(dp), allocatable :: u(:), v(:), a(:), un(:), vn(:), an(:)
      real(dp) :: t0 = 0.0_dp                   !< the time of (un, vn, an)
      !> per contact at the end of the step: penetration δ and force (the mean force p/h of
      !> an impulse), as the method defines them
      real(dp), allocatable :: pen(:), force(:)
      real(dp), allocatable :: mrow(:)          !< M·1: gravity and ground-motion loads
      integer, allocatable :: fixed_nodes(:)
      type(mech_state_t) :: ms                  !< links and penalty contacts, committed
      !> what to change when the run diverges (ends the observer's message)
      character(len=:), allocatable :: advice
      !> the energy the method conserves is ½vᵀMv − ke_aMa·aᵀMa (h²/8 for velocity Verlet,
      !> 0 for the others): the observer's kinetic energy in the balance
      real(dp) :: ke_aMa = 0.0_dp
   contains
      procedure(stepper_init), deferred :: init
      procedure(stepper_step), deferred :: step
   end type stepper_t

   abstract interface
      !> Everything the method needs, allocated once; the state at t = 0 (u, v, a, pen,
      !> force, ms committed). stat /= MARTELLO_OK with the observer's message on failure.
      subroutine stepper_init(self, m, s, o, stat)
         import :: stepper_t, model_t, integrator_settings_t, observer_t
         class(stepper_t), intent(inout) :: self
         type(model_t), intent(in) :: m
         type(integrator_settings_t), intent(in) :: s
         type(observer_t), intent(inout) :: o
         integer, intent(out) :: stat
      end subroutine stepper_init
      !> One step from (un, vn, an) at t0 to (u, v, a) at t = t0 + h, committed, with its
      !> work increments, the phases of the contacts the method resolves itself and its
      !> counters handed to o. stat /= MARTELLO_OK: the method failed (observer_fail).
      subroutine stepper_step(self, m, t, o, stat)
         import :: stepper_t, model_t, observer_t, dp
         class(stepper_t), intent(inout) :: self
         type(model_t), intent(in) :: m
         real(dp), intent(in) :: t
         type(observer_t), intent(inout) :: o
         integer, intent(out) :: stat
      end subroutine stepper_step
   end interface

contains

   !> The common start of every stepper: sizes, the initial state (fixed nodes at rest), M·1
   !> and the committed link and contact states at t = 0.
   subroutine stepper_start(self, m, s)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      integer :: n, j
      n = m%n
      self%n = n; self%nc = m%ncontact; self%h = s%dt
      allocate (self%u(0:n), self%v(0:n), self%a(0:n), self%un(0:n), self%vn(0:n), &
                self%an(0:n), self%mrow(0:n), self%pen(m%ncontact), self%force(m%ncontact))
      self%u(0) = 0.0_dp; self%v(0) = 0.0_dp; self%a = 0.0_dp
      self%u(1:n) = m%u0; self%v(1:n) = merge(0.0_dp, m%v0, m%fixed)
      self%pen = 0.0_dp; self%force = 0.0_dp
      self%fixed_nodes = pack([(j, j = 1, n)], m%fixed)
      self%un = 1.0_dp; self%un(0) = 0.0_dp
      call mass_times(m, self%un, self%mrow)
      call mech_init(m, self%ms, self%u, self%v)
      self%un = self%u; self%vn = self%v; self%an = self%a
   end subroutine stepper_start

   !> The start of the structural steppers: stepper_start, then a = M⁻¹(f_ext − f_int) at
   !> t = 0 (fint, fext of length 0:n; mband of the model's bandwidth), the states committed.
   subroutine stepper_rest_start(self, m, s, mband, fint, fext, o, stat)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(band_t), intent(inout) :: mband
      real(dp), intent(inout) :: fint(0:), fext(0:)
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      logical :: ok
      stat = MARTELLO_OK
      call stepper_start(self, m, s)
      call internal_forces(m, self%ms, self%u, self%v, fint)
      call external_forces(m, self%mrow, 0.0_dp, fext)
      self%a = fext - fint
      call solve_free_mass(m, self%fixed_nodes, mband, self%a, ok)
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      if (.not. ok) then
         call stepper_fail(o, MARTELLO_ERR_SINGULAR, 0.0_dp, 'the mass matrix is singular on the free nodes', stat)
         return
      end if
      call mech_commit(m, self%ms, self%u)
      self%pen = self%ms%con_pen; self%force = self%ms%con_f
   end subroutine stepper_rest_start

   !> rhs ← M⁻¹ rhs on the free nodes (fixed rows and rhs entries 0); mband of the model's
   !> bandwidth, reassembled here. ok = .false. if M is singular there.
   subroutine solve_free_mass(m, fixed_nodes, mband, rhs, ok)
      type(model_t), intent(in) :: m
      integer, intent(in) :: fixed_nodes(:)
      type(band_t), intent(inout) :: mband
      real(dp), intent(inout) :: rhs(0:)
      logical, intent(out) :: ok
      integer :: k
      call band_zero(mband)
      call assemble_mass(m, 1.0_dp, mband)
      do k = 1, size(fixed_nodes)
         call band_pin(mband, fixed_nodes(k)); rhs(fixed_nodes(k)) = 0.0_dp
      end do
      call band_solve(mband, rhs(1:m%n), ok)
      rhs(0) = 0.0_dp
   end subroutine solve_free_mass

   !> The method failed at t: what happened, and when.
   subroutine stepper_fail(o, code, t, what, stat)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: code
      real(dp), intent(in) :: t
      character(len=*), intent(in) :: what
      integer, intent(out) :: stat
      character(len=len(what) + 32) :: msg
      write (msg, '(a,a,es12.5,a)') what, ' (t = ', t, ' s)'
      call observer_fail(o, code, t, msg, stat)
   end subroutine stepper_fail
end module martello_stepper
