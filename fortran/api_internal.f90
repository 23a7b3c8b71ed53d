!> The door between the kernels and the C integrators (c/martello_internal.h, not public):
!> the scene's topology, force evaluation, and the observer of the run (martello_observer,
!> docs/run-layer.md), through which they measure a run as the fixed-step methods do.
module martello_api_internal
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model
   use martello_evaluator
   use martello_switching, only: switch_count, stepped_across, ACROSS_CONTINUOUS, &
      ACROSS_RATE_BOUNDED
   use martello_contact_laws, only: P_RESTITUTION
   use martello_element_rows, only: row_dot, rows_terms
   use martello_integrator_settings, only: integrator_settings_t
   use martello_observer
   use martello_run_quantities, only: NCOUNTERS
   use martello_run, only: run_t
   use martello_api_handles, only: get_model, get_run, get_eval, get_observer
   implicit none
   private

contains

   integer(c_int) function c_model_topology(handle, n, nc, mass, fixed, scheme, &
                                            gap, restitution, ncoupling) bind(C, name='martello_model_topology')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n, nc, ncoupling
      type(c_ptr), value :: mass, fixed, scheme, gap, restitution
      type(model_t), pointer :: mp
      real(c_double), pointer :: pm(:), pg(:), pe(:)
      integer(c_int), pointer :: pf(:), ps(:)
      mp => get_model(handle)
      c_model_topology = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      n = mp%n; nc = mp%ncontact; ncoupling = mp%ncoupling
      if (c_associated(mass)) then
         call c_f_pointer(mass, pm, [n]); pm = mp%mass
      end if
      if (c_associated(fixed)) then
         call c_f_pointer(fixed, pf, [n]); pf = merge(1, 0, mp%fixed)
      end if
      if (nc > 0) then
         if (c_associated(scheme)) then
            call c_f_pointer(scheme, ps, [nc]); ps = mp%con_scheme(1:nc)
         end if
         if (c_associated(gap)) then
            call c_f_pointer(gap, pg, [nc]); pg = mp%con_gap(1:nc)
         end if
         if (c_associated(restitution)) then
            call c_f_pointer(restitution, pe, [nc]); pe = mp%con_par(P_RESTITUTION, 1:nc)
         end if
      end if
      c_model_topology = MARTELLO_OK
   end function c_model_topology

   !> The rows of the elements (martello_element_rows, docs/buildings.md): links first, then
   !> contacts — element e (0-based) is link e + 1 for e < n_links, else contact e − n_links + 1
   !> — with terms first[e] … first[e + 1] − 1 (0-based) of node (0-based) and coef. With first,
   !> node, coef NULL only the sizes: n_links and n_terms (all elements' terms).
   integer(c_int) function c_model_elements(handle, n_links, n_terms, first, node, coef) &
      bind(C, name='martello_model_elements')
      type(c_ptr), value :: handle, first, node, coef
      integer(c_int), intent(out) :: n_links, n_terms
      type(model_t), pointer :: mp
      integer(c_int), pointer :: pfirst(:), pnode(:)
      real(c_double), pointer :: pcoef(:)
      integer :: ne, tl, tc
      mp => get_model(handle)
      c_model_elements = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      tl = rows_terms(mp%lnk); tc = rows_terms(mp%con)
      n_links = mp%nlink; n_terms = tl + tc
      ne = mp%nlink + mp%ncontact
      if (c_associated(first)) then
         call c_f_pointer(first, pfirst, [ne + 1])
         pfirst(1:mp%nlink + 1) = mp%lnk%first(1:mp%nlink + 1) - 1
         pfirst(mp%nlink + 1:ne + 1) = mp%con%first(1:mp%ncontact + 1) - 1 + tl
      end if
      if (c_associated(node) .and. n_terms > 0) then
         call c_f_pointer(node, pnode, [n_terms])
         pnode(1:tl) = mp%lnk%node(1:tl) - 1; pnode(tl + 1:) = mp%con%node(1:tc) - 1
      end if
      if (c_associated(coef) .and. n_terms > 0) then
         call c_f_pointer(coef, pcoef, [n_terms])
         pcoef(1:tl) = mp%lnk%coef(1:tl); pcoef(tl + 1:) = mp%con%coef(1:tc)
      end if
      c_model_elements = MARTELLO_OK
   end function c_model_elements

   !> Initial displacements and velocities of the nodes (fixed nodes: u0, v = 0).
   integer(c_int) function c_model_initial_state(handle, u0, v0) bind(C, name='martello_model_initial_state')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u0(*), v0(*)
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_initial_state = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      call model_initial_state(mp, u0(1:mp%n), v0(1:mp%n))
      c_model_initial_state = MARTELLO_OK
   end function c_model_initial_state

   integer(c_int) function c_eval_create(mhandle, handle) bind(C, name='martello_eval_create')
      type(c_ptr), value :: mhandle
      type(c_ptr), intent(out) :: handle
      type(model_t), pointer :: mp
      type(evaluator_t), pointer :: ep
      integer :: st
      handle = c_null_ptr
      mp => get_model(mhandle)
      c_eval_create = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      allocate (ep, stat=st)
      if (st /= 0) then
         c_eval_create = MARTELLO_ERR_MEMORY; return
      end if
      call evaluator_init(ep, mp, st)
      if (st /= MARTELLO_OK) then
         deallocate (ep); c_eval_create = st; return
      end if
      handle = c_loc(ep)
      c_eval_create = MARTELLO_OK
   end function c_eval_create

   subroutine c_eval_free(handle) bind(C, name='martello_eval_free')
      type(c_ptr), intent(inout) :: handle
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      if (associated(ep)) deallocate (ep)
      handle = c_null_ptr
   end subroutine c_eval_free

   integer(c_int) function c_eval_acceleration(handle, t, u, v, a) bind(C, name='martello_eval_acceleration')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: a(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_acceleration = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_acceleration(ep, t, u(1:ep%m%n), v(1:ep%m%n), a(1:ep%m%n), ok)
      c_eval_acceleration = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_acceleration

   integer(c_int) function c_eval_forces(handle, t, u, v, fint, fext) bind(C, name='martello_eval_forces')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: fint(*), fext(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_forces = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_forces(ep, t, u(1:ep%m%n), v(1:ep%m%n), fint(1:ep%m%n), fext(1:ep%m%n))
      c_eval_forces = MARTELLO_OK
   end function c_eval_forces

   integer(c_int) function c_eval_solve_mass(handle, x) bind(C, name='martello_eval_solve_mass')
      type(c_ptr), value :: handle
      real(c_double), intent(inout) :: x(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_solve_mass = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_solve_mass(ep, x(1:ep%m%n), ok)
      c_eval_solve_mass = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_solve_mass

   integer(c_int) function c_eval_commit(handle, u, v) bind(C, name='martello_eval_commit')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_commit = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_commit(ep, u(1:ep%m%n), v(1:ep%m%n))
      c_eval_commit = MARTELLO_OK
   end function c_eval_commit

   !> martello_eval_save / martello_eval_restore (evaluator_save, evaluator_restore).
   integer(c_int) function c_eval_save(handle) bind(C, name='martello_eval_save')
      type(c_ptr), value :: handle
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_save = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_save(ep)
      c_eval_save = MARTELLO_OK
   end function c_eval_save

   integer(c_int) function c_eval_restore(handle) bind(C, name='martello_eval_restore')
      type(c_ptr), value :: handle
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_restore = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_restore(ep)
      c_eval_restore = MARTELLO_OK
   end function c_eval_restore

   !> The half-bandwidth kd of the model's node couplings (model_bandwidth) and whether its
   !> mass is lumped (no couplings: M⁻¹ diagonal).
   integer(c_int) function c_eval_bandwidth(handle, kd, lumped) bind(C, name='martello_eval_bandwidth')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: kd, lumped
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      kd = 0; lumped = 0
      c_eval_bandwidth = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      kd = model_bandwidth(ep%m)
      lumped = merge(1, 0, ep%m%ncoupling == 0)
      c_eval_bandwidth = MARTELLO_OK
   end function c_eval_bandwidth

   !> K_t and C_t at (u, v) in band storage (evaluator_tangent): n columns of 3 kd + 1.
   integer(c_int) function c_eval_tangent(handle, u, v, k, c) bind(C, name='martello_eval_tangent')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: k(*), c(*)
      type(evaluator_t), pointer :: ep
      integer :: kd, n
      ep => get_eval(handle)
      c_eval_tangent = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      n = ep%m%n
      kd = model_bandwidth(ep%m)
      call tangent(k(1:(3*kd + 1)*n), c(1:(3*kd + 1)*n))
      c_eval_tangent = MARTELLO_OK
   contains
      subroutine tangent(kf, cf)
         real(c_double), intent(out), target :: kf(:), cf(:)
         real(dp), pointer, contiguous :: k2(:, :), c2(:, :)
         k2(1:3*kd + 1, 1:n) => kf
         c2(1:3*kd + 1, 1:n) => cf
         call evaluator_tangent(ep, u(1:n), v(1:n), k2, c2)
      end subroutine tangent
   end function c_eval_tangent

   !> Event-driven integrators: hold the laws on smooth branches (evaluator_use_branches).
   integer(c_int) function c_eval_use_branches(handle, nsw) bind(C, name='martello_eval_use_branches')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: nsw
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      nsw = 0
      c_eval_use_branches = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_use_branches(ep)
      nsw = switch_count(ep%m)
      c_eval_use_branches = MARTELLO_OK
   end function c_eval_use_branches

   !> Adaptive integrators that step across continuous kinks (docs/sundials-ode.md, events
   !> inside the steps): the penalty contacts of the class laws (ACROSS_CONTINUOUS: the force
   !> continuous at its switches; ACROSS_RATE_BOUNDED: its rate bounded too) are left whole,
   !> the other laws held on branches; continuous(j) = 1 for each penalty contact left whole
   !> (its onsets and separations are the caller's to locate), 0 for the others.
   integer(c_int) function c_eval_use_smooth_branches(handle, laws, nsw, continuous) &
      bind(C, name='martello_eval_use_smooth_branches')
      type(c_ptr), value :: handle
      integer(c_int), value :: laws
      integer(c_int), intent(out) :: nsw
      integer(c_int), intent(out) :: continuous(*)
      type(evaluator_t), pointer :: ep
      integer :: j
      ep => get_eval(handle)
      nsw = 0
      c_eval_use_smooth_branches = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      if (laws /= ACROSS_CONTINUOUS .and. laws /= ACROSS_RATE_BOUNDED) return
      call evaluator_use_branches(ep, across=int(laws))
      nsw = switch_count(ep%m)
      do j = 1, ep%m%ncontact
         continuous(j) = merge(1, 0, ep%ms%is_penalty(j) .and. stepped_across(ep%m, j, int(laws)))
      end do
      c_eval_use_smooth_branches = MARTELLO_OK
   end function c_eval_use_smooth_branches

   integer(c_int) function c_eval_set_onset_speed(handle, contact, v) &
      bind(C, name='martello_eval_set_onset_speed')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      real(c_double), value :: v
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_set_onset_speed = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      if (contact < 0 .or. contact >= ep%m%ncontact) return
      call evaluator_set_onset_speed(ep, int(contact) + 1, v)
      c_eval_set_onset_speed = MARTELLO_OK
   end function c_eval_set_onset_speed

   integer(c_int) function c_eval_switches(handle, el, alpha, beta, gamma) &
      bind(C, name='martello_eval_switches')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: el(*)
      real(c_double), intent(out) :: alpha(*), beta(*), gamma(*)
      type(evaluator_t), pointer :: ep
      integer :: ns
      ep => get_eval(handle)
      c_eval_switches = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      ns = switch_count(ep%m)
      if (ns > 0) call evaluator_switches(ep, el(1:ns), alpha(1:ns), beta(1:ns), gamma(1:ns))
      c_eval_switches = MARTELLO_OK
   end function c_eval_switches

   integer(c_int) function c_eval_next_breakpoint(handle, t, tb) bind(C, name='martello_eval_next_breakpoint')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(out) :: tb
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      tb = huge(1.0_dp)
      c_eval_next_breakpoint = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      tb = evaluator_next_breakpoint(ep, t)
      c_eval_next_breakpoint = MARTELLO_OK
   end function c_eval_next_breakpoint

   !> The shortest period of the loads' harmonic terms, or huge() (docs/sundials-ode.md, held
   !> contacts).
   integer(c_int) function c_eval_load_period(handle, period) bind(C, name='martello_eval_load_period')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: period
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      period = huge(1.0_dp)
      c_eval_load_period = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      period = evaluator_load_period(ep)
      c_eval_load_period = MARTELLO_OK
   end function c_eval_load_period

   !> The number of links of the evaluator's scene.
   integer(c_int) function c_eval_link_count(handle, n_links) bind(C, name='martello_eval_link_count')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n_links
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      n_links = 0
      c_eval_link_count = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      n_links = ep%m%nlink
      c_eval_link_count = MARTELLO_OK
   end function c_eval_link_count

   !> The rates of the peak quantities at (t, u, v) with accelerations a (evaluator_rates):
   !> per contact pen, pen_rate, force, force_rate; per link du, dv, lf, lf_rate; per node the
   !> jerk. MARTELLO_ERR_SINGULAR for a singular mass matrix.
   integer(c_int) function c_eval_rates(handle, t, u, v, a, pen, pen_rate, force, force_rate, &
                                        du, dv, lf, lf_rate, jerk) bind(C, name='martello_eval_rates')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*)
      real(c_double), intent(out) :: pen(*), pen_rate(*), force(*), force_rate(*), du(*), dv(*), &
                                     lf(*), lf_rate(*), jerk(*)
      type(evaluator_t), pointer :: ep
      integer :: n, nc, nl
      logical :: ok
      ep => get_eval(handle)
      c_eval_rates = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      n = ep%m%n; nc = ep%m%ncontact; nl = ep%m%nlink
      call evaluator_rates(ep, t, u(1:n), v(1:n), a(1:n), pen(1:nc), pen_rate(1:nc), force(1:nc), &
                           force_rate(1:nc), du(1:nl), dv(1:nl), lf(1:nl), lf_rate(1:nl), &
                           jerk(1:n), ok)
      c_eval_rates = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_rates

   integer(c_int) function c_eval_power(handle, power) bind(C, name='martello_eval_power')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: power(5)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_power = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_power(ep, power)
      c_eval_power = MARTELLO_OK
   end function c_eval_power

   integer(c_int) function c_eval_energy(handle, u, v, kinetic, recoverable) bind(C, name='martello_eval_energy')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: kinetic, recoverable
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_energy = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_energy(ep, u(1:ep%m%n), v(1:ep%m%n), kinetic, recoverable)
      c_eval_energy = MARTELLO_OK
   end function c_eval_energy

   integer(c_int) function c_run_settings(handle, s) bind(C, name='martello_run_settings')
      type(c_ptr), value :: handle
      type(integrator_settings_t), intent(out) :: s
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_settings = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      s = rp%settings
      c_run_settings = MARTELLO_OK
   end function c_run_settings

   integer(c_int) function c_run_observer(handle, obs) bind(C, name='martello_run_observer')
      type(c_ptr), value :: handle
      type(c_ptr), intent(out) :: obs
      type(run_t), pointer :: rp
      rp => get_run(handle)
      obs = c_null_ptr
      c_run_observer = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      obs = c_loc(rp%results)
      c_run_observer = MARTELLO_OK
   end function c_run_observer

   !> The C integrators evaluate the energies at every sample: an adaptive step costs far
   !> more than their evaluation.
   integer(c_int) function c_observer_begin(handle, ehandle, u, v, advice) &
      bind(C, name='martello_observer_begin')
      type(c_ptr), value :: handle, ehandle
      real(c_double), intent(in) :: u(*), v(*)
      character(kind=c_char), intent(in) :: advice(*)
      type(observer_t), pointer :: op
      type(evaluator_t), pointer :: ep
      integer :: st
      op => get_observer(handle); ep => get_eval(ehandle)
      c_observer_begin = MARTELLO_ERR_ARGUMENT
      if (.not. (associated(op) .and. associated(ep))) return
      call evaluator_load(ep, u(1:ep%m%n), v(1:ep%m%n))
      ! the observer's arrays for the C integrators' states (a fixed-step run needs none)
      st = 0
      if (.not. allocated(op%acc)) allocate (op%acc(0:ep%m%n), op%c_pen(ep%m%ncontact), &
                                            op%c_force(ep%m%ncontact), stat=st)
      if (st /= 0) then
         call out_of_memory('the states of the results of a run', &
                            REAL_BYTES*(ep%m%n + 1.0_dp + 2.0_dp*ep%m%ncontact), FIX_SMALLER_SCENE, &
                            st, op%message)
      else
         ! the C integrators conserve ½vᵀMv itself (no Verlet correction): a = 0 serves
         op%acc = 0.0_dp
         call observer_begin(op, ep%m, ep%ms, ep%u, ep%v, op%acc, 1, c_string(advice), 0.0_dp, st)
      end if
      ! a failure is the observer's (its message set): the run ends with it
      if (st /= MARTELLO_OK) call observer_failed(op, 0.0_dp, st)
      c_observer_begin = st
   end function c_observer_begin

   integer(c_int) function c_observer_sample(handle, ehandle, t, u, v, a, force, k) &
      bind(C, name='martello_observer_sample')
      type(c_ptr), value :: handle, ehandle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), force(*)
      integer(c_int), value :: k
      c_observer_sample = sample_from_c(handle, ehandle, t, u, v, a, force, k, .false.)
   end function c_observer_sample

   !> A step of a method that samples the scene only where all of it stands at one time (local
   !> stepping, docs/sundials-ode.md): a step of the budget at t (max_steps, max_wall, the
   !> progress callback), no sample. MARTELLO_ERR_LIMIT or MARTELLO_ERR_INTERRUPTED with the
   !> message when the run must stop.
   integer(c_int) function c_observer_step(handle, t) bind(C, name='martello_observer_step')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      type(observer_t), pointer :: op
      integer :: stat
      op => get_observer(handle)
      c_observer_step = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      op%nsamples = op%nsamples + 1
      stat = MARTELLO_OK
      call observer_watch(op, t, stat)
      c_observer_step = stat
   end function c_observer_step

   !> An output row on the method's interpolant inside a step (martello_observer_row):
   !> measured and recorded as a sample, off the energy grid and the step budget.
   integer(c_int) function c_observer_row(handle, ehandle, t, u, v, a, force, k) &
      bind(C, name='martello_observer_row')
      type(c_ptr), value :: handle, ehandle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), force(*)
      integer(c_int), value :: k
      c_observer_row = sample_from_c(handle, ehandle, t, u, v, a, force, k, .true.)
   end function c_observer_row

   integer(c_int) function sample_from_c(handle, ehandle, t, u, v, a, force, k, row) result(res)
      type(c_ptr), value :: handle, ehandle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), force(*)
      integer(c_int), value :: k
      logical, intent(in) :: row
      type(observer_t), pointer :: op
      type(evaluator_t), pointer :: ep
      integer :: n, j, stat
      op => get_observer(handle); ep => get_eval(ehandle)
      res = MARTELLO_ERR_ARGUMENT
      if (.not. (associated(op) .and. associated(ep))) return
      n = ep%m%n
      call evaluator_load(ep, u(1:n), v(1:n))
      op%acc(0) = 0.0_dp; op%acc(1:n) = a(1:n)
      ! δ of every contact; the forces of the penalty contacts and the link states are the
      ! evaluator's, committed at this state
      do j = 1, ep%m%ncontact
         op%c_pen(j) = row_dot(ep%m%con, j, ep%u) - ep%m%con_gap(j)
         op%c_force(j) = merge(ep%ms%con_f(j), force(j), ep%ms%is_penalty(j))
      end do
      call observer_sample(op, ep%m, ep%ms, t, ep%u, ep%v, op%acc, op%c_pen, op%c_force, int(k), &
                           stat, ep%ms%link_f, ep%ms%link_u, row=row)
      res = stat
   end function sample_from_c

   !> A located extremum of node `node` (0-based) at t, value u; maximum = 1 for a maximum.
   integer(c_int) function c_observer_extremum(handle, node, t, u, maximum) &
      bind(C, name='martello_observer_extremum')
      type(c_ptr), value :: handle
      integer(c_int), value :: node, maximum
      real(c_double), value :: t, u
      type(observer_t), pointer :: op
      op => get_observer(handle)
      c_observer_extremum = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      if (node < 0 .or. node >= op%n_nodes) return
      call observer_extremum(op, node + 1, t, u, maximum /= 0)
      c_observer_extremum = MARTELLO_OK
   end function c_observer_extremum

   !> A peak of kind (PEAK_*, as fortran/run_quantities.f90) of item index (0-based node,
   !> contact or link) located by the method inside a step, value q.
   integer(c_int) function c_observer_peak(handle, kind, index, q) &
      bind(C, name='martello_observer_peak')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, index
      real(c_double), value :: q
      type(observer_t), pointer :: op
      op => get_observer(handle)
      c_observer_peak = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      if (index < 0 .or. index >= peak_items(op, kind)) return
      call observer_peak(op, kind, index + 1, q)
      c_observer_peak = MARTELLO_OK
   end function c_observer_peak

   !> The value a located peak of kind, index must exceed to count (observer_peak_value).
   integer(c_int) function c_observer_peak_value(handle, kind, index, q) &
      bind(C, name='martello_observer_peak_value')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, index
      real(c_double), intent(out) :: q
      type(observer_t), pointer :: op
      op => get_observer(handle)
      q = 0.0_dp
      c_observer_peak_value = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      if (index < 0 .or. index >= peak_items(op, kind)) return
      q = observer_peak_value(op, kind, index + 1)
      c_observer_peak_value = MARTELLO_OK
   end function c_observer_peak_value

   integer(c_int) function c_observer_work(handle, w_ext, w_int, w_links, w_contact, w_impact) &
      bind(C, name='martello_observer_work')
      type(c_ptr), value :: handle
      real(c_double), value :: w_ext, w_int, w_links, w_contact, w_impact
      type(observer_t), pointer :: op
      op => get_observer(handle)
      c_observer_work = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      call observer_work(op, external=w_ext, links=w_links, contact=w_contact, impact=w_impact, &
                         internal=w_int)
      c_observer_work = MARTELLO_OK
   end function c_observer_work

   !> open = 1: contact starts a phase at t approaching at v; 0: ends it at t leaving at v.
   integer(c_int) function c_observer_set_phase(handle, contact, open, t, v) &
      bind(C, name='martello_observer_set_phase')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact, open
      real(c_double), value :: t, v
      type(observer_t), pointer :: op
      op => observer_of(handle, contact)
      c_observer_set_phase = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      if (open /= 0) then
         call observer_open_phase(op, int(contact) + 1, t, v)
      else if (op%ph_open(contact + 1)) then
         call observer_close_phase(op, int(contact) + 1, t, v)
      end if
      c_observer_set_phase = MARTELLO_OK
   end function c_observer_set_phase

   integer(c_int) function c_observer_add_impact(handle, contact, t, v_in, v_out, pen, force) &
      bind(C, name='martello_observer_add_impact')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      real(c_double), value :: t, v_in, v_out, pen, force
      type(observer_t), pointer :: op
      op => observer_of(handle, contact)
      c_observer_add_impact = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      call observer_add_impact(op, int(contact) + 1, t, v_in, v_out, pen, force)
      c_observer_add_impact = MARTELLO_OK
   end function c_observer_add_impact

   !> 1 while contact is in a phase, else 0 (also for a null handle or a contact out of range).
   integer(c_int) function c_observer_in_phase(handle, contact) bind(C, name='martello_observer_in_phase')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      type(observer_t), pointer :: op
      op => observer_of(handle, contact)
      c_observer_in_phase = 0
      if (associated(op)) c_observer_in_phase = merge(1, 0, op%ph_open(contact + 1))
   end function c_observer_in_phase

   integer(c_int) function c_observer_add_counts(handle, inc) bind(C, name='martello_observer_add_counts')
      type(c_ptr), value :: handle
      integer(c_long_long), intent(in) :: inc(NCOUNTERS)
      type(observer_t), pointer :: op
      op => get_observer(handle)
      c_observer_add_counts = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      op%counters = op%counters + inc
      c_observer_add_counts = MARTELLO_OK
   end function c_observer_add_counts

   !> Returns status (the method's failure code) once recorded, MARTELLO_ERR_ARGUMENT for a
   !> null handle; a null message is the observer's non-finite divergence.
   integer(c_int) function c_observer_fail(handle, status, t_reached, message) bind(C, name='martello_observer_fail')
      type(c_ptr), value :: handle
      integer(c_int), value :: status
      real(c_double), value :: t_reached
      type(c_ptr), value :: message
      character(kind=c_char), pointer :: cs(:)
      type(observer_t), pointer :: op
      integer :: stat
      op => get_observer(handle)
      c_observer_fail = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      if (c_associated(message)) then
         call c_f_pointer(message, cs, [512])
         call observer_fail(op, int(status), t_reached, c_string(cs), stat)
      else
         call observer_fail_nonfinite(op, t_reached, stat)
      end if
      c_observer_fail = stat
   end function c_observer_fail

   integer(c_int) function c_observer_finish(handle, t_reached) bind(C, name='martello_observer_finish')
      type(c_ptr), value :: handle
      real(c_double), value :: t_reached
      type(observer_t), pointer :: op
      op => get_observer(handle)
      c_observer_finish = MARTELLO_ERR_ARGUMENT
      if (.not. associated(op)) return
      call observer_finish(op, t_reached)
      c_observer_finish = MARTELLO_OK
   end function c_observer_finish

   !> The observer of a handle if contact (0-based) is one of its contacts, else null.
   function observer_of(handle, contact) result(op)
      type(c_ptr), value :: handle
      integer(c_int), intent(in) :: contact
      type(observer_t), pointer :: op
      op => get_observer(handle)
      if (.not. associated(op)) return
      if (contact < 0 .or. contact >= size(op%ph_open)) op => null()
   end function observer_of

   !> A NUL-terminated C string as a Fortran one (at most 512 characters).
   function c_string(cs) result(fs)
      character(kind=c_char), intent(in) :: cs(*)
      character(len=:), allocatable :: fs
      integer :: i, st
      do i = 1, 512
         if (cs(i) == c_null_char) exit
      end do
      allocate (character(len=i - 1) :: fs, stat=st)
      ! at most 512 bytes, and no status to return: the process' one line (out_of_memory)
      if (st /= 0) call out_of_memory('a message passed through the C API', 512.0_dp, FIX_SMALLER_SCENE)
      fs = transfer(cs(1:i - 1), fs)
   end function c_string
end module martello_api_internal
