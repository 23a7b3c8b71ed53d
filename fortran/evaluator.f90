!> Force evaluation of a scene for integrators that live outside the Fortran kernels (GSL
!> and SUNDIALS adapters in c/): the accelerations M⁻¹(f_ext − f_int), contact gaps, mass
!> solves for impulses, energies, and the commit of path-dependent link states at accepted
!> steps. It wraps the same assembly code as the structural integrators.
module martello_evaluator
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, model_bandwidth, model_initial_state, model_u0
   use martello_assembly
   use martello_band_matrix
   use martello_switching, only: switch_count, switching_choose, switching_functions, ACROSS_NONE
   use martello_element_rows, only: row_dot, row_add
   implicit none
   private
   public :: evaluator_t, evaluator_init, evaluator_load, evaluator_acceleration, &
      evaluator_forces, evaluator_solve_mass, evaluator_commit, &
      evaluator_energy, evaluator_power, evaluator_use_branches, evaluator_switches, &
      evaluator_set_onset_speed, &
      evaluator_next_breakpoint, evaluator_load_period, evaluator_rates, evaluator_tangent, evaluator_save, evaluator_restore

   type :: evaluator_t
      type(model_t), pointer :: m => null()
      type(mech_state_t) :: ms
      !> the element states of evaluator_save, for evaluator_restore
      type(mech_state_t) :: saved
      type(band_t) :: mband
      real(dp), allocatable :: mrow(:), u(:), v(:), f(:), fext(:), work(:)
      integer, allocatable :: fixed_nodes(:)
      !> laws held on smooth branches between located switches (martello_switching)
      logical :: branches = .false.
      !> ... except the penalty contacts stepped across (switching_choose: ACROSS_*)
      integer :: across = ACROSS_NONE
   end type evaluator_t

contains

   !> stat: MARTELLO_ERR_MEMORY (the model's message its line) if its arrays cannot be
   !> allocated.
   subroutine evaluator_init(ev, m, stat)
      type(evaluator_t), intent(inout) :: ev
      type(model_t), intent(inout), target :: m
      integer, intent(out) :: stat
      integer :: n, j
      ev%m => m
      n = m%n
      allocate (ev%mrow(0:n), ev%u(0:n), ev%v(0:n), ev%f(0:n), ev%fext(0:n), ev%work(0:n), &
                ev%fixed_nodes(count(m%fixed)), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the force evaluator', REAL_BYTES*6*(n + 1.0_dp) &
                            + INT_BYTES*count(m%fixed), FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      call load_pattern(m, ev%work, ev%mrow)
      ev%u = 0.0_dp; ev%v = 0.0_dp
      call model_initial_state(m, ev%u(1:n), ev%v(1:n))
      call mech_init(m, ev%ms, ev%u, ev%v, stat, m%errmsg)
      if (stat == MARTELLO_OK) call band_init(ev%mband, n, model_bandwidth(m), stat, m%errmsg)
      ev%fixed_nodes = pack([(j, j = 1, n)], m%fixed)
   end subroutine evaluator_init

   !> ev%u, ev%v (0:n, 0 = ground) ← (u, v), fixed nodes at u0 and at rest.
   subroutine evaluator_load(ev, u, v)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: u(:), v(:)
      integer :: j
      ev%u(1:) = u; ev%v(1:) = v
      ev%u(ev%fixed_nodes) = [(model_u0(ev%m, ev%fixed_nodes(j)), j = 1, size(ev%fixed_nodes))]
      ev%v(ev%fixed_nodes) = 0.0_dp
   end subroutine evaluator_load

   !> fint and fext (length n) at (t, u, v); links from the committed state.
   subroutine evaluator_forces(ev, t, u, v, fint, fext)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: t, u(:), v(:)
      real(dp), intent(out) :: fint(:), fext(:)
      call evaluator_load(ev, u, v)
      call internal_forces(ev%m, ev%ms, ev%u, ev%v, ev%f)
      call external_forces(ev%m, ev%mrow, t, ev%fext)
      fint = ev%f(1:); fext = ev%fext(1:)
   end subroutine evaluator_forces

   !> a = M⁻¹(fext − fint) on the free nodes, 0 on fixed ones; ok = .false. if M is singular.
   subroutine evaluator_acceleration(ev, t, u, v, a, ok)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: t, u(:), v(:)
      real(dp), intent(out) :: a(:)
      logical, intent(out) :: ok
      real(dp) :: fint(size(a)), fext(size(a))
      call evaluator_forces(ev, t, u, v, fint, fext)
      a = fext - fint
      call evaluator_solve_mass(ev, a, ok)
   end subroutine evaluator_acceleration

   !> x ← M⁻¹x on the free nodes (fixed rows give 0): accelerations, or velocity jumps from
   !> impulses.
   subroutine evaluator_solve_mass(ev, x, ok)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(inout) :: x(:)
      logical, intent(out) :: ok
      integer :: k, i
      if (ev%m%ncoupling == 0) then
         x = x/merge(1.0_dp, ev%m%mass, ev%m%fixed)
         x(ev%fixed_nodes) = 0.0_dp
         ok = .true.
         return
      end if
      call band_zero(ev%mband)
      call assemble_mass(ev%m, 1.0_dp, ev%mband)
      do k = 1, size(ev%fixed_nodes)
         i = ev%fixed_nodes(k)
         call band_pin(ev%mband, i)
         x(i) = 0.0_dp
      end do
      call band_solve(ev%mband, x, ok)
   end subroutine evaluator_solve_mass

   !> Accept (u, v) as the state at the end of a step: path-dependent links commit.
   !> Keep every element state (committed and trial, branches, onset speeds): an output row
   !> inside a step is committed for its own values and the step's states are then restored,
   !> so that no later step depends on where the rows fall (docs/sundials-ode.md, output rows).
   subroutine evaluator_save(ev)
      type(evaluator_t), intent(inout) :: ev
      ev%saved = ev%ms
   end subroutine evaluator_save

   !> The element states of the last evaluator_save.
   subroutine evaluator_restore(ev)
      type(evaluator_t), intent(inout) :: ev
      ev%ms = ev%saved
   end subroutine evaluator_restore

   subroutine evaluator_commit(ev, u, v)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: u(:), v(:)
      call evaluator_load(ev, u, v)
      call internal_forces(ev%m, ev%ms, ev%u, ev%v, ev%f)
      call mech_commit(ev%m, ev%ms, ev%u)
      if (ev%branches) call switching_choose(ev%m, ev%ms, ev%u, ev%v, ev%across)
   end subroutine evaluator_commit

   !> From now on the laws are held on smooth branches, chosen at the committed state and
   !> changed at commits past their switches (docs/event-driven.md, switching surfaces).
   !> across (ACROSS_*): the penalty contacts left whole, stepped across (switching_choose).
   subroutine evaluator_use_branches(ev, across)
      type(evaluator_t), intent(inout) :: ev
      integer, intent(in), optional :: across
      ev%branches = .true.
      if (present(across)) ev%across = across
      call switching_choose(ev%m, ev%ms, ev%u, ev%v, ev%across)
   end subroutine evaluator_use_branches

   !> The approach speed at the located onset of penalty contact j's phase (the Hunt-Crossley
   !> family's v_in, chi = a/v_in), for a contact committed in contact: an integrator that
   !> steps across the onset knows it only after the step, on its interpolant.
   subroutine evaluator_set_onset_speed(ev, j, v)
      type(evaluator_t), intent(inout) :: ev
      integer, intent(in) :: j
      real(dp), intent(in) :: v
      if (ev%ms%con_on(j)) ev%ms%con_vin(j) = max(v, ONSET_SPEED_FLOOR)
   end subroutine evaluator_set_onset_speed

   !> The switches of the branches held (martello_switching): switch_count slots.
   subroutine evaluator_switches(ev, el, alpha, beta, gamma)
      type(evaluator_t), intent(in) :: ev
      integer, intent(out) :: el(:)
      real(dp), intent(out) :: alpha(:), beta(:), gamma(:)
      call switching_functions(ev%m, ev%ms, el, alpha, beta, gamma)
   end subroutine evaluator_switches

   !> The first time after t where a load of the scene has a kink (tf_next_breakpoint), or
   !> huge().
   pure function evaluator_next_breakpoint(ev, t) result(tb)
      type(evaluator_t), intent(in) :: ev
      real(dp), intent(in) :: t
      real(dp) :: tb
      tb = load_breakpoint(ev%m, t)
   end function evaluator_next_breakpoint

   !> The shortest period of the loads' harmonic terms (load_period), or huge().
   pure function evaluator_load_period(ev) result(p)
      type(evaluator_t), intent(in) :: ev
      real(dp) :: p
      p = load_period(ev%m)
   end function evaluator_load_period

   !> The rates of the peak quantities at the state (t, u, v) with accelerations a (length
   !> n), on the laws' branches held (docs/run-layer.md, located peaks): per contact δ, δ̇,
   !> the force P (penalty contacts; 0 for the others) and Ṗ = P_δ δ̇ + P_δ̇ δ̈; per link the
   !> elongation du, du̇, the force f and ḟ = f_du du̇ + f_du̇ dü; per node the jerk
   !> ȧ = M⁻¹(ḟ_ext − ḟ_int), ḟ_int the sum of the element rates (a stiffness block's
   !> K v + C a), ḟ_ext a centred difference in time of the loads (smooth between the stops at
   !> their kinks). ok = .false. if M is singular.
   subroutine evaluator_rates(ev, t, u, v, a, pen, pen_rate, force, force_rate, du, dv, lf, &
                              lf_rate, jerk, ok)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: t, u(:), v(:), a(:)
      real(dp), intent(out) :: pen(:), pen_rate(:), force(:), force_rate(:), du(:), dv(:), &
                               lf(:), lf_rate(:), jerk(:)
      logical, intent(out) :: ok
      real(dp) :: ltan(2, ev%m%nlink), ctan(2, ev%m%ncontact), acc(0:ev%m%n), fd(0:ev%m%n), &
                  fp(0:ev%m%n), eps
      integer :: j
      associate (m => ev%m)
         call evaluator_load(ev, u, v)
         acc(0) = 0.0_dp; acc(1:) = a
         call internal_forces(m, ev%ms, ev%u, ev%v, ev%f, link_tan=ltan, con_tan=ctan)
         eps = sqrt(epsilon(1.0_dp))*max(abs(t), 1.0e-3_dp)
         call external_forces(m, ev%mrow, t + eps, fp)
         call external_forces(m, ev%mrow, t - eps, fd)
         fd = (fp - fd)/(2.0_dp*eps)
         do j = 1, m%ncontact
            pen(j) = row_dot(m%con, j, ev%u) - m%con_gap(j)
            pen_rate(j) = row_dot(m%con, j, ev%v)
            force(j) = 0.0_dp; force_rate(j) = 0.0_dp
            if (.not. ev%ms%is_penalty(j)) cycle
            force(j) = ev%ms%con_f_trial(j)
            force_rate(j) = ctan(1, j)*pen_rate(j) + ctan(2, j)*row_dot(m%con, j, acc)
            call row_add(m%con, j, -force_rate(j), fd)
         end do
         do j = 1, m%nlink
            du(j) = row_dot(m%lnk, j, ev%u); dv(j) = row_dot(m%lnk, j, ev%v)
            lf(j) = ev%ms%link_f_trial(j)
            lf_rate(j) = ltan(1, j)*dv(j) + ltan(2, j)*row_dot(m%lnk, j, acc)
            call row_add(m%lnk, j, -lf_rate(j), fd)
         end do
         do j = 1, m%nblock
            associate (nd => m%block(j)%node)
               fd(nd) = fd(nd) - matmul(m%block(j)%k, ev%v(nd))
               if (m%block(j)%damped) fd(nd) = fd(nd) - matmul(m%block(j)%c, acc(nd))
            end associate
         end do
         jerk = fd(1:)
         call evaluator_solve_mass(ev, jerk, ok)
      end associate
   end subroutine evaluator_rates

   !> The tangent stiffness K_t = ∂f_int/∂u and damping C_t = ∂f_int/∂v at (u, v), on the
   !> laws' branches held, in the band layout of martello_band_matrix (A(i,j) in
   !> k(2kd+1+i−j, j), kd = model_bandwidth; ldab = 3kd + 1): the analytic Jacobian of the
   !> first-order form (docs/sundials-ode.md).
   subroutine evaluator_tangent(ev, u, v, k, c)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: u(:), v(:)
      real(dp), intent(out), contiguous :: k(:, :), c(:, :)
      k = 0.0_dp; c = 0.0_dp
      call evaluator_load(ev, u, v)
      call internal_forces(ev%m, ev%ms, ev%u, ev%v, ev%f, k, 1.0_dp, 0.0_dp, c)
   end subroutine evaluator_tangent

   !> The powers at the state of the last force evaluation: of the external and the internal
   !> forces on the free nodes, f·v, and of the dampers, the other links and the penalty
   !> contacts (element_power): the integrands of a run's works.
   subroutine evaluator_power(ev, power)
      type(evaluator_t), intent(in) :: ev
      real(dp), intent(out) :: power(5)
      integer :: i
      power(1:2) = 0.0_dp
      do i = 1, ev%m%n
         if (ev%m%fixed(i)) cycle
         power(1) = power(1) + ev%fext(i)*ev%v(i)
         power(2) = power(2) + ev%f(i)*ev%v(i)
      end do
      call element_power(ev%m, ev%ms, ev%v, power(3), power(4), power(5))
   end subroutine evaluator_power

   subroutine evaluator_energy(ev, u, v, kinetic, recoverable)
      type(evaluator_t), intent(inout) :: ev
      real(dp), intent(in) :: u(:), v(:)
      real(dp), intent(out) :: kinetic, recoverable
      real(dp) :: el, ec
      call evaluator_load(ev, u, v)
      kinetic = kinetic_energy(ev%m, ev%v, ev%work)
      call recoverable_energy(ev%m, ev%ms, ev%u, el, ec)
      recoverable = el + ec
   end subroutine evaluator_energy
end module martello_evaluator
