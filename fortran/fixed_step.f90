!> The fixed-step strategy and the interface of its one-step methods (docs/run-layer.md):
!> one time loop, t_k = k·h until t_end is reached (never a shortened step), the phases of
!> the penalty contacts located on the free side of each step, one observer sample per
!> step. A stepper owns one step of its method — its state, its solves, its impulses — and
!> hands the observer its work increments, the phases it resolves itself, its counters and
!> failures. A new fixed-step integrator: a type extending stepper_t (init, step) in one
!> file, one row of the integrator registry, one case of run_dynamic's dispatch.
module martello_fixed_step
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_initial_state
   use martello_element_rows, only: row_dot
   use martello_assembly, only: mech_state_t, mech_init, load_pattern, assemble_mass, internal_forces, &
      external_forces, mech_commit
   use martello_band_matrix, only: band_t, band_zero, band_pin, band_solve
   use martello_integrator_settings, only: integrator_settings_t, integrator_name
   use martello_run_checks, only: check_run_settings
   use martello_observer, only: observer_t, observer_begin, observer_sample, observer_fail, observer_failed, &
      observer_penalty_phases, observer_finish
   use martello_run_quantities, only: C_STEPS, C_FACTORIZATIONS
   implicit none
   private
   public :: run_fixed_step, stepper_t, stepper_start, stepper_rest_start, solve_free_mass, &
      stepper_fail, newmark_kinematics, newmark_predictor, newmark_increment, &
      contact_state

   !> Samples between energy evaluations (kinetic and recoverable energy are two passes over
   !> the model, as dear as a cheap step): a NaN is caught at once through the works.
   integer, parameter :: ENERGY_CHECK = 16

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
      real(dp), allocatable :: mrow(:)          !< M·ι: gravity and ground-motion loads
      integer, allocatable :: fixed_nodes(:)
      type(mech_state_t) :: ms                  !< links and penalty contacts, committed
      !> what to change when the run diverges (ends the observer's message)
      character(len=:), allocatable :: advice
      !> the energy the method conserves is ½vᵀMv − ke_aMa·aᵀMa (h²/8 for velocity Verlet,
      !> 0 for the others): the observer's kinetic energy in the balance
      real(dp) :: ke_aMa = 0.0_dp
      !> the method measures its states itself, item by item in its own sweeps (the fused
      !> chain step): its measure_start and measure hand them to the observer, phases
      !> included (the strategy's observer_penalty_phases is then not called)
      logical :: measures_itself = .false.
      !> the method's velocity jumps from v_k to v_{k+1} inside the step (Moreau–Jean: the
      !> positions are q_k + h((1−θ)v_k + θv_{k+1})): a penalty phase then starts at v_k of
      !> the step it opens in and ends at v_{k+1} of the step it closes in, the velocities
      !> the method carries on with (docs/moreau-jean.md "Penalty contacts"), not a value
      !> extrapolated with the step's mean acceleration, which holds the contact force
      logical :: velocity_jump_phases = .false.
   contains
      procedure(stepper_init), deferred :: init
      procedure(stepper_step), deferred :: step
      !> (un, vn, an) ← (u, v, a) before a step: copies; a method that writes every entry of
      !> u, v, a before reading it may swap the buffers instead
      procedure :: begin_step => stepper_begin_step
      !> the observer's start (observer_begin: stat = MARTELLO_ERR_MEMORY, the run failed, if
      !> its arrays cannot be allocated), and the sample of the state at grid point k
      !> (observer_sample); a method that measures itself overrides both
      procedure :: measure_start => stepper_measure_start
      procedure :: measure => stepper_measure
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

   !> Run the scene from t = 0 to t_end with the stepper stp. stat < 0 on failure, with
   !> o%message saying where and why (the results so far stay in o for diagnosis).
   subroutine run_fixed_step(m, s, o, stp, stat)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      class(stepper_t), intent(inout) :: stp
      integer, intent(out) :: stat
      integer(i8) :: k
      real(dp) :: t
      real(dp), allocatable :: no_acc(:)

      call check_run_settings(m, s, o%message, stat)
      if (stat /= MARTELLO_OK) return
      call stp%init(m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      ! velocity-jump phases: located and valued with the end velocities (no acceleration)
      if (stp%velocity_jump_phases) then
         allocate (no_acc(0:stp%n), source=0.0_dp, stat=stat)
         if (stat /= 0) then
            call out_of_memory('the zero acceleration of the velocity-jump phases', &
                               REAL_BYTES*(stp%n + 1.0_dp), FIX_SMALLER_SCENE, stat, o%message)
            call observer_failed(o, 0.0_dp, stat)
            return
         end if
      end if
      ! the other methods' states lie on a smooth motion between phase changes: their peaks
      ! are located inside the steps (docs/results.md)
      o%smooth_steps = .not. stp%velocity_jump_phases
      call stp%measure_start(m, o, ENERGY_CHECK, stat)
      if (stat /= MARTELLO_OK) return
      t = 0.0_dp
      call stp%measure(m, o, t, 0_i8, stat)
      if (stat /= MARTELLO_OK) return

      do k = 1_i8, o%n_grid      ! 64-bit: more than 2^31 steps are counted, not wrapped
         call stp%begin_step()
         stp%t0 = t
         t = real(k, dp)*stp%h
         call stp%step(m, t, o, stat)
         if (stat /= MARTELLO_OK) return
         o%counters(C_STEPS) = o%counters(C_STEPS) + 1_i8
         if (stp%measures_itself) then
            ! its phases are handed over with its sample (measure)
         else if (stp%velocity_jump_phases) then
            call observer_penalty_phases(o, m, stp%ms, stp%un, stp%vn, no_acc, stp%u, stp%v, no_acc, &
                                         t, stp%h)
         else
            call observer_penalty_phases(o, m, stp%ms, stp%un, stp%vn, stp%an, stp%u, stp%v, stp%a, &
                                         t, stp%h)
         end if
         call stp%measure(m, o, t, k, stat)
         if (stat /= MARTELLO_OK) return
      end do
      call observer_finish(o, t)
   end subroutine run_fixed_step

   !> The observer's start: the state at t = 0 and the energy evaluation cadence.
   subroutine stepper_measure_start(self, m, o, energy_interval, stat)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: energy_interval
      integer, intent(out) :: stat
      call observer_begin(o, m, self%ms, self%u, self%v, self%a, energy_interval, self%advice, &
                          self%ke_aMa, stat)
      if (stat /= MARTELLO_OK) call observer_failed(o, 0.0_dp, stat)
   end subroutine stepper_measure_start

   !> The state at t = t_k; the previous one is the stepper's own (un, vn, an): no copy.
   subroutine stepper_measure(self, m, o, t, k, stat)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer(i8), intent(in) :: k
      integer, intent(out) :: stat
      call observer_sample(o, m, self%ms, t, self%u, self%v, self%a, self%pen, self%force, k, stat, &
                           self%ms%link_f, self%ms%link_u, self%un(1:), self%vn(1:), self%an(1:))
   end subroutine stepper_measure

   !> The start of a step: the committed state becomes (un, vn, an).
   subroutine stepper_begin_step(self)
      class(stepper_t), intent(inout) :: self
      self%un = self%u; self%vn = self%v; self%an = self%a
   end subroutine stepper_begin_step

   !> The common start of every stepper: sizes, the initial state (fixed nodes at rest), M·1
   !> and the committed link and contact states at t = 0. stat = MARTELLO_ERR_MEMORY, the run
   !> failed (observer_fail), if they cannot be allocated.
   subroutine stepper_start(self, m, s, o, stat)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, j, k
      character(len=512) :: msg
      n = m%n
      self%n = n; self%nc = m%ncontact; self%h = s%dt
      allocate (self%u(0:n), self%v(0:n), self%a(0:n), self%un(0:n), self%vn(0:n), &
                self%an(0:n), self%mrow(0:n), self%pen(m%ncontact), self%force(m%ncontact), &
                self%fixed_nodes(count(m%fixed)), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the state of '//integrator_name(s%kind), &
                            REAL_BYTES*(7*(n + 1.0_dp) + 2.0_dp*m%ncontact) &
                            + INT_BYTES*count(m%fixed), FIX_SMALLER_SCENE, stat, msg)
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%u(0) = 0.0_dp; self%v(0) = 0.0_dp; self%a = 0.0_dp
      call model_initial_state(m, self%u(1:n), self%v(1:n))
      self%pen = 0.0_dp; self%force = 0.0_dp
      k = 0
      do j = 1, n
         if (.not. m%fixed(j)) cycle
         k = k + 1; self%fixed_nodes(k) = j
      end do
      call load_pattern(m, self%un, self%mrow)
      call mech_init(m, self%ms, self%u, self%v, stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
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
      call stepper_start(self, m, s, o, stat)
      if (stat /= MARTELLO_OK) return
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
      call contact_state(self, m)
   end subroutine stepper_rest_start

   !> pen and force of every contact at the current state: penalty contacts from their
   !> committed law, the others δ = u_a − u_b − gap and the force the method gives them
   !> (a multiplier, or an impulse over impulse_step: its mean force).
   subroutine contact_state(self, m, rigid_force, impulse_step)
      class(stepper_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in), optional :: rigid_force(:), impulse_step
      integer :: k
      do k = 1, m%ncontact
         if (self%ms%is_penalty(k)) then
            self%pen(k) = self%ms%con_pen(k); self%force(k) = self%ms%con_f(k)
         else
            self%pen(k) = row_dot(m%con, k, self%u) - m%con_gap(k)
            self%force(k) = rigid_force(k)
            if (present(impulse_step)) self%force(k) = rigid_force(k)/impulse_step
         end if
      end do
   end subroutine contact_state

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

   !> The Newmark relations for the trial u of a step: a(u), v(u) with (β, γ) = (bt, gm); the
   !> fixed nodes at u0 and at rest.
   subroutine newmark_kinematics(self, bt, gm)
      class(stepper_t), intent(inout) :: self
      real(dp), intent(in) :: bt, gm
      integer :: i, k, n
      real(dp) :: h
      n = self%n; h = self%h
      associate (u => self%u, v => self%v, a => self%a, un => self%un, vn => self%vn, an => self%an)
         a(1:n) = (u(1:n) - un(1:n) - h*vn(1:n))/(bt*h*h) - (0.5_dp - bt)/bt*an(1:n)
         v(1:n) = vn(1:n) + h*((1.0_dp - gm)*an(1:n) + gm*a(1:n))
         do k = 1, size(self%fixed_nodes)
            i = self%fixed_nodes(k)
            u(i) = un(i); v(i) = 0.0_dp; a(i) = 0.0_dp
         end do
      end associate
   end subroutine newmark_kinematics

   !> The constant-acceleration predictor of a step: u = uₙ + h vₙ + ½h² aₙ with the (v, a)
   !> the Newmark relations give it, v = vₙ + h aₙ and a = aₙ, written directly (any β, γ);
   !> the fixed nodes at uₙ and at rest.
   subroutine newmark_predictor(self)
      class(stepper_t), intent(inout) :: self
      integer :: n
      real(dp) :: h
      n = self%n; h = self%h
      self%u(1:n) = self%un(1:n) + h*self%vn(1:n) + 0.5_dp*h*h*self%an(1:n)
      self%v(1:n) = self%vn(1:n) + h*self%an(1:n)
      self%a(1:n) = self%an(1:n)
      call rest_fixed_nodes(self)
   end subroutine newmark_predictor

   !> A Newton increment du of u (0 on the fixed nodes) and the increments of a and v the
   !> Newmark relations tie to it, Δa = du/(βh²), Δv = γ du/(βh) (bt, gm = β, γ). The state
   !> moves by increments: a is never taken back from u − uₙ − h vₙ, whose rounding,
   !> ε|u|, it would carry as ε|u|/(βh²) — on a sub-step τ ≪ h (event-split steps) an
   !> acceleration the next stretch's trapezoid turns into a velocity error hε|u|/(2βτ²)
   !> (docs/integrators.md, rounding of the Newmark family).
   subroutine newmark_increment(self, du, bt, gm)
      class(stepper_t), intent(inout) :: self
      real(dp), intent(in) :: du(:), bt, gm
      integer :: n
      real(dp) :: h
      n = self%n; h = self%h
      self%u(1:n) = self%u(1:n) + du
      self%v(1:n) = self%v(1:n) + (gm/(bt*h))*du
      self%a(1:n) = self%a(1:n) + du/(bt*h*h)
   end subroutine newmark_increment

   !> The fixed nodes at uₙ and at rest.
   subroutine rest_fixed_nodes(self)
      class(stepper_t), intent(inout) :: self
      integer :: i, k
      do k = 1, size(self%fixed_nodes)
         i = self%fixed_nodes(k)
         self%u(i) = self%un(i); self%v(i) = 0.0_dp; self%a(i) = 0.0_dp
      end do
   end subroutine rest_fixed_nodes

   !> The method failed at t: what happened, and when.
   subroutine stepper_fail(o, code, t, what, stat)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: code
      real(dp), intent(in) :: t
      character(len=*), intent(in) :: what
      integer, intent(out) :: stat
      character(len=len(what) + 32) :: msg
      write (msg, '(a,a,a,a)') what, ' (t = ', sci(t, 5), ' s)'
      call observer_fail(o, code, t, msg, stat)
   end subroutine stepper_fail
end module martello_fixed_step
