!> The observer of a dynamic run (docs/run-layer.md): the history and its recording
!> cadence, contact phases, peaks, the energy balance, divergence detection, the counters
!> and the final message, for every integrator. The methods (martello_fixed_step's steppers,
!> the C integrators through c/martello_internal.h) hand it accepted states, work
!> increments and the phase changes they locate. results_t is what a finished run exposes
!> (martello_api_results); observer_t adds the working state of the measurement.
module martello_observer
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_assembly, only: mech_state_t, kinetic_energy, recoverable_energy, mass_times, &
      load_breakpoint
   use martello_links, only: link_force, LINK_SPRING, LINK_BAR, LINK_BILINEAR, LINK_DASHPOT, &
      LINK_FLUID_DAMPER, L_STIFF
   use martello_contact_laws, only: contact_force, LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING
   use martello_integrator_settings, only: integrator_settings_t, integrator_name
   use martello_run_quantities
   use martello_registry, only: INTEGRATORS
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite, ieee_is_nan
   use, intrinsic :: iso_c_binding, only: c_funptr, c_ptr, c_null_funptr, c_null_ptr, &
      c_associated, c_f_procpointer, c_int, c_double, c_long_long
   implicit none
   private
   public :: results_t, observer_t, observer_init, observer_begin, observer_sample, &
      observer_work, observer_open_phase, observer_close_phase, observer_add_impact, &
      observer_penalty_phases, observer_fail, observer_fail_nonfinite, observer_finish, &
      free_side_crossing, progress_callback, observer_extremum, observer_recorded, &
      observer_peak, observer_peak_value, peak_items, observer_link_step_extremum, &
      observer_link_step_peaks, &
      PEAK_V, PEAK_A, PEAK_PEN, PEAK_FORCE, PEAK_LINK_FORCE, PEAK_LINK_DU, &
      NCOUNTERS, C_STEPS, C_REJECTED, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS, &
      C_JACOBIANS, C_ROOT_EVALS, C_CHATTER, NENERGY, E_KINETIC, E_RECOVERABLE, E_INPUT, E_DAMPING, &
      E_PLASTIC, E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT, NEVENT, EV_T_ON, EV_T_OFF, &
      EV_V_IN, EV_V_OUT, EV_MAX_PEN, EV_MAX_FORCE

   type :: results_t
      ! history: hist(:, k) = [t, (u, v, a of each output node), (δ, P of each output
      ! contact), (force, elongation of each output link), energy(1:NENERGY)]
      integer :: ncol = 0, nrec = 0
      real(dp), allocatable :: hist(:, :)
      integer, allocatable :: out_nodes(:), out_contacts(:), out_links(:)
      ! events: one per contact phase
      integer :: nevents = 0
      integer, allocatable :: ev_contact(:)
      real(dp), allocatable :: ev(:, :)
      ! peaks over every accepted step and located inside the steps (docs/results.md): the
      ! adaptive methods hand theirs (observer_extremum, observer_peak), the fixed-step ones
      ! are located on each step's polynomial (track)
      real(dp), allocatable :: u_max(:), u_min(:), v_absmax(:), a_absmax(:)
      !> the largest local maximum of u (u_peak at t_peak)
      real(dp), allocatable :: u_peak(:), t_peak(:)
      !> the largest |u| and its time
      real(dp), allocatable :: u_absmax(:), t_absmax(:)
      !> a fixed-step method: the extrema of u and v are located on each step's cubic Hermite
      !> (hermite_extremum, hermite_v_extremum)
      logical :: fixed_steps = .false.
      real(dp), allocatable :: pen_max(:), force_max(:)
      !> per link: max |force| and max |elongation| (storey shear and drift of a frame)
      real(dp), allocatable :: link_force_absmax(:), link_du_absmax(:)
      integer, allocatable :: impacts(:)
      real(dp) :: energy(NENERGY) = 0.0_dp
      real(dp) :: energy_balance_max = 0.0_dp   !< max |balance| over the run
      integer(i8) :: counters(NCOUNTERS) = 0_i8
      real(dp) :: t_end_reached = 0.0_dp
      real(dp) :: dt_critical = 0.0_dp          !< explicit stability limit (0: not computed)
      real(dp) :: omega_max = 0.0_dp
      character(len=512) :: message = ''
   end type results_t

   type, extends(results_t) :: observer_t
      ! what the run asked for
      integer :: kind = 0, every = 1
      integer(i8) :: n_grid = 1                 !< output grid points t = k·dt, k = 1 … n_grid
      real(dp) :: divergence_factor = 10.0_dp
      ! energy: evaluated every energy_interval-th sample (and where recorded)
      integer :: energy_interval = 1
      integer(i8) :: nsamples = -1              !< accepted steps so far (t = 0 is sample 0)
      ! the budget (max_steps, max_wall [s], 0: none) and the caller's progress callback,
      ! watched every WATCH_EVERY samples (observer_watch)
      real(dp) :: t_end = 0.0_dp, max_steps = huge(1.0_dp), max_wall = 0.0_dp
      integer(i8) :: clock0 = 0, clock_last = 0, clock_rate = 1
      type(c_funptr) :: progress = c_null_funptr
      type(c_ptr) :: progress_user = c_null_ptr
      character(len=:), allocatable :: advice   !< ends a divergence message: what to change
      real(dp) :: e0 = 0.0_dp, e_links0 = 0.0_dp, e_cont0 = 0.0_dp, ke_corr0 = 0.0_dp
      !> the method conserves ½vᵀMv − ke_aMa·aᵀMa (central difference: h²/8; else 0)
      real(dp) :: ke_aMa = 0.0_dp
      ! works since t = 0; w_abs = Σ|ΔW_ext| (the divergence scale); w_last the last ΔW_ext
      real(dp) :: w_ext = 0.0_dp, w_abs = 0.0_dp, w_last = 0.0_dp, d_damp = 0.0_dp, &
                  d_links = 0.0_dp, d_contact = 0.0_dp, d_impact = 0.0_dp
      ! open contact phases: onset time and speed, running maxima of δ and P
      logical, allocatable :: ph_open(:)
      real(dp), allocatable :: ph_t(:), ph_v(:), ph_pen(:), ph_f(:)
      ! the previous accepted state, for the interpolated peaks when the method keeps none
      real(dp), allocatable :: prev_u(:), prev_v(:), prev_a(:)
      real(dp) :: prev_t = -1.0_dp
      real(dp), allocatable :: work(:)          !< scratch (0:n): M v
      !> a C integrator's accelerations (0:n), contact penetrations and forces
      real(dp), allocatable :: acc(:), c_pen(:), c_force(:)
      !> the fixed-step method's states lie on one smooth motion between the phase changes
      !> (not Moreau–Jean's velocity jumps): the peaks of a, δ, the contact and link forces
      !> and elongations are located on its steps (track)
      logical :: smooth_steps = .false.
      !> per node (0:n): the time of the last phase change (onset, separation, impact) of a
      !> contact at it; the chatter resolutions at the previous sample (the jumps of the
      !> forces a located peak of |a| must not straddle)
      real(dp), allocatable :: node_change(:)
      integer, allocatable :: con_nodes(:, :)
      integer(i8) :: chatter_prev = 0_i8
      !> per contact: its force and force rate at the previous sample, while in contact there;
      !> the linear and Kelvin laws' k and c, contiguous (read at every step of a chain)
      real(dp), allocatable :: c_prev_f(:), c_prev_fr(:), c_k(:), c_c(:)
      !> the peak of |a| on fixed steps (a_parabolas): a sample k that raised it waits two
      !> samples for the parabola through k − 1, k, k + 1 and the smoothness test with k + 2.
      !> Per node: a at k − 1, k, k + 1 and the sample k of its latest candidate (a_gen);
      !> the candidates of the last two samples (pend1: k = the last, pend2: the one before),
      !> with the time and the chatter count of their sample k − 1
      real(dp), allocatable :: a_m1(:), a_0(:), a_p1(:)
      integer(i8), allocatable :: a_gen(:)
      integer, allocatable :: pend1(:), pend2(:)
      integer :: npend1 = 0, npend2 = 0
      real(dp) :: pend1_t0 = 0.0_dp, pend2_t0 = 0.0_dp
      integer(i8) :: pend1_stamp = 0_i8, pend2_stamp = 0_i8
   end type observer_t

   !> The caller's progress callback (martello_run_set_progress): the simulated time, t_end,
   !> the steps taken and the wall-clock seconds since the start; a non-zero return stops the
   !> run (MARTELLO_ERR_INTERRUPTED).
   abstract interface
      integer(c_int) function progress_callback(user, t, t_end, steps, elapsed) bind(C)
         import :: c_int, c_ptr, c_double, c_long_long
         type(c_ptr), value :: user
         real(c_double), value :: t, t_end, elapsed
         integer(c_long_long), value :: steps
      end function progress_callback
   end interface

   !> Samples between looks at the clock (a system_clock call costs about a cheap step's
   !> arithmetic), and seconds between two progress reports.
   integer, parameter :: WATCH_EVERY = 32
   real(dp), parameter :: PROGRESS_INTERVAL = 0.25_dp
   !> Energy the contacts and impacts may create, as a share of the initial energy + input
   !> work, before the run is a failure: far above what the catalogue's fixed steps leave
   !> (≤ 1e-4: the trapezoidal work of a contact closing within a step), far below a
   !> realised restitution past 1 (e = 1.1 creates 21 % of the impact's energy).
   real(dp), parameter :: CREATED_BOUND = 1.0e-2_dp
   !> History rows allocated at the start; it grows by doubling beyond (record).
   integer, parameter :: HIST_START = 4096

   !> Samples of one observer_sample call: the grid point k as a default or a 64-bit integer.
   interface observer_sample
      module procedure observer_sample_i8, observer_sample_i4
   end interface observer_sample

contains

   !> Size the results of a run (every integrator) and take the settings the measurement
   !> needs: the output grid t = k·dt, k ≤ n_grid (whole intervals until t_end is reached:
   !> the last one is reported as t_reached, never a shortened one labelled t_end), the
   !> recording cadence and the divergence rule.
   !> The budget: a run whose output grid alone needs more than max_steps steps is refused
   !> before it starts (every integrator takes at least one step per grid point);
   !> stat = MARTELLO_ERR_LIMIT, or MARTELLO_ERR_MEMORY if the arrays cannot be allocated.
   subroutine observer_init(o, s, n_nodes, n_contacts, out_nodes, out_contacts, capacity, &
                            n_links, out_links, stat)
      type(observer_t), intent(inout) :: o
      type(integrator_settings_t), intent(in) :: s
      integer, intent(in) :: n_nodes, n_contacts, out_nodes(:), out_contacts(:), capacity, &
                             n_links, out_links(:)
      integer, intent(out), optional :: stat
      type(observer_t) :: fresh
      real(dp) :: steps
      integer :: st, st2
      o = fresh        ! every field at its default, every array deallocated
      if (present(stat)) stat = MARTELLO_OK
      o%kind = s%kind
      if (s%kind >= 1 .and. s%kind <= size(INTEGRATORS)) o%fixed_steps = .not. INTEGRATORS(s%kind)%adaptive
      o%every = max(s%every, 1); o%divergence_factor = s%divergence_factor
      o%t_end = s%t_end; o%max_steps = s%max_steps; o%max_wall = s%max_wall
      call system_clock(o%clock0, o%clock_rate)
      o%clock_last = o%clock0
      steps = 1.0_dp
      if (s%dt > 0.0_dp .and. s%t_end > 0.0_dp) steps = max(1.0_dp, s%t_end/s%dt*(1.0_dp - 1.0e-12_dp))
      if (steps > o%max_steps .or. .not. ieee_is_finite(steps)) then
         write (o%message, '(a,a,es10.3,a,es10.3,a)') integrator_name(o%kind), ': the run needs at least ', &
            steps, ' steps (t_end/dt), more than max_steps = ', o%max_steps, &
            ': raise dt, shorten t_end or raise max_steps'
         if (present(stat)) stat = MARTELLO_ERR_LIMIT
         steps = 1.0_dp
      end if
      o%n_grid = ceiling(steps, i8)
      o%out_nodes = out_nodes; o%out_contacts = out_contacts; o%out_links = out_links
      o%ncol = 1 + 3*size(out_nodes) + 2*size(out_contacts) + 2*size(out_links) + NENERGY
      allocate (o%hist(o%ncol, max(min(capacity, HIST_START), 2)), o%ev(NEVENT, 16), o%ev_contact(16), &
                stat=st)
      allocate (o%u_max(n_nodes), o%u_min(n_nodes), o%v_absmax(n_nodes), o%a_absmax(n_nodes), &
                o%pen_max(n_contacts), o%force_max(n_contacts), o%impacts(n_contacts), &
                o%u_peak(n_nodes), o%t_peak(n_nodes), o%link_force_absmax(n_links), &
                o%u_absmax(n_nodes), o%t_absmax(n_nodes), &
                o%link_du_absmax(n_links), o%prev_u(n_nodes), o%prev_v(n_nodes), &
                o%prev_a(n_nodes), o%work(0:n_nodes), o%acc(0:n_nodes), o%c_pen(n_contacts), &
                o%c_force(n_contacts), o%ph_open(n_contacts), o%c_prev_f(n_contacts), &
                o%c_prev_fr(n_contacts), o%a_m1(n_nodes), o%a_0(n_nodes), o%a_p1(n_nodes), &
                o%a_gen(n_nodes), o%pend1(n_nodes), o%pend2(n_nodes), &
                o%ph_t(n_contacts), o%ph_v(n_contacts), o%ph_pen(n_contacts), o%ph_f(n_contacts), &
                stat=st2)
      if (st /= 0 .or. st2 /= 0) then
         write (o%message, '(a,i0,a,i0,a)') 'out of memory allocating the results of a run of ', &
            n_nodes, ' nodes and ', n_contacts, ' contacts'
         if (present(stat)) stat = MARTELLO_ERR_MEMORY
         if (st2 /= 0) error stop 'martello: out of memory allocating the results of a run'
         if (.not. allocated(o%hist)) allocate (o%hist(o%ncol, 2))
         if (.not. allocated(o%ev)) allocate (o%ev(NEVENT, 16), o%ev_contact(16))
      end if
      ! NaN until a state is tracked (a run that fails before its first step)
      o%link_force_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      o%link_du_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      o%u_peak = -huge(1.0_dp); o%t_peak = -1.0_dp
      o%u_absmax = -1.0_dp; o%t_absmax = -1.0_dp
      o%u_max = -huge(1.0_dp); o%u_min = huge(1.0_dp); o%v_absmax = 0.0_dp
      o%a_absmax = 0.0_dp; o%pen_max = -huge(1.0_dp); o%force_max = 0.0_dp; o%impacts = 0
      o%ph_open = .false.
      o%c_prev_f = 0.0_dp; o%c_prev_fr = 0.0_dp; o%a_gen = -10_i8
   end subroutine observer_init

   !> The state at t = 0, before its first sample: the initial energies the balance starts
   !> from, and a phase opened at t = 0 for every penalty contact closed there. energy_interval: samples between energy evaluations (the strategy's choice: 16
   !> for cheap fixed steps, 1 for adaptive ones); advice ends a divergence message;
   !> ke_aMa: the method conserves ½vᵀMv − ke_aMa·aᵀMa (Verlet; 0 for the others).
   subroutine observer_begin(o, m, ms, u, v, a, energy_interval, advice, ke_aMa)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: u(0:), v(0:), a(0:)
      integer, intent(in) :: energy_interval
      character(len=*), intent(in) :: advice
      real(dp), intent(in) :: ke_aMa
      real(dp) :: e_kin
      integer :: c
      o%con_nodes = reshape([(m%con_a(c), m%con_b(c), c = 1, m%ncontact)], [2, m%ncontact])
      o%c_k = m%con_par(P_STIFF, 1:m%ncontact)
      o%c_c = merge(m%con_par(P_DAMPING, 1:m%ncontact), 0.0_dp, m%con_law(1:m%ncontact) == LAW_KELVIN)
      allocate (o%node_change(0:m%n), source=-huge(1.0_dp))
      do c = 1, m%ncontact
         if (ms%con_on(c)) call observer_open_phase(o, c, 0.0_dp, v(m%con_a(c)) - v(m%con_b(c)))
      end do
      e_kin = kinetic_energy(m, v, o%work)
      call recoverable_energy(m, ms, u, o%e_links0, o%e_cont0)
      o%e0 = e_kin + o%e_links0 + o%e_cont0
      o%ke_aMa = ke_aMa
      ! the balance starts from the method's conserved energy e0 − ke_corr
      o%ke_corr0 = o%e0 - (o%e0 - kinetic_correction(o, m, a))
      o%energy_interval = max(energy_interval, 1)
      o%advice = advice
   end subroutine observer_begin

   !> Work increments of one step [J]: external, of the dampers, of the other links and of
   !> the penalty contacts (a fixed step: mech_commit's trapezoidal works), and the kinetic
   !> energy impulses took out. A method that integrates the works along its solution (the C
   !> integrators) may hand the total internal work instead of the dampers': damping is then
   !> internal − links − contact.
   subroutine observer_work(o, external, damping, links, contact, impact, internal)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in), optional :: external, damping, links, contact, impact, internal
      if (present(external)) then
         o%w_ext = o%w_ext + external; o%w_abs = o%w_abs + abs(external)
         o%w_last = external
      end if
      if (present(internal)) then
         o%d_damp = o%d_damp + (internal - links - contact)
      else if (present(damping)) then
         o%d_damp = o%d_damp + damping
      end if
      if (present(links)) o%d_links = o%d_links + links
      if (present(contact)) o%d_contact = o%d_contact + contact
      if (present(impact)) o%d_impact = o%d_impact + impact
   end subroutine observer_work

   !> ke_aMa·aᵀMa: velocity Verlet conserves ½vᵀMv − (h²/8)aᵀMa exactly against trapezoidal
   !> work (the a-terms of ΔKE telescope), so its balance is an identity to round-off, like
   !> average acceleration's (docs/integrators.md "energy balance").
   real(dp) function kinetic_correction(o, m, a) result(kc)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: a(0:)
      kc = 0.0_dp
      if (o%ke_aMa == 0.0_dp) return
      call mass_times(m, a, o%work)
      kc = o%ke_aMa*dot_product(a(1:m%n), o%work(1:m%n))
   end function kinetic_correction

   !> The recording cadence: t = 0, every every-th output grid point, and the last one.
   pure logical function recorded(o, k)
      type(observer_t), intent(in) :: o
      integer(i8), intent(in) :: k
      recorded = k == 0
      if (k > 0) recorded = mod(k, int(o%every, i8)) == 0 .or. k >= o%n_grid
   end function recorded

   !> Whether the state at grid point k is a history row (a method that keeps some states
   !> lazily builds them for these samples only).
   pure logical function observer_recorded(o, k)
      type(observer_t), intent(in) :: o
      integer(i8), intent(in) :: k
      observer_recorded = recorded(o, k)
   end function observer_recorded

   !> An accepted state at t (once per accepted step and at t = 0, after the step's phase
   !> changes): phase maxima and peaks; the energy terms and the divergence test where
   !> recorded, every energy_interval-th sample and once a work is not finite; a history row
   !> where recorded. k: the grid point t = k·dt of the state, or −1. u, v, a on nodes 0:n;
   !> u_prev … the previous state if the method keeps it (saves a copy). stat:
   !> MARTELLO_ERR_DIVERGED, with the message, when the run must stop.
   subroutine observer_sample_i8(o, m, ms, t, u, v, a, pen, force, k, stat, link_f, link_du, &
                                 u_prev, v_prev, a_prev)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
      integer(i8), intent(in) :: k
      integer, intent(out) :: stat
      real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
      real(dp) :: e_kin, e_links, e_cont, kc
      logical :: due
      integer :: c
      stat = MARTELLO_OK
      o%nsamples = o%nsamples + 1
      due = recorded(o, k) .or. mod(o%nsamples, int(o%energy_interval, i8)) == 0 .or. &
            .not. ieee_is_finite(o%w_last + o%d_damp + o%d_links + o%d_contact + o%d_impact)
      do c = 1, size(pen)
         if (.not. o%ph_open(c)) cycle
         o%ph_pen(c) = max(o%ph_pen(c), pen(c)); o%ph_f(c) = max(o%ph_f(c), force(c))
      end do
      call track(o, m, ms, t, u(1:), v(1:), a(1:), pen, force, link_f, link_du, u_prev, v_prev, &
                 a_prev)
      if (due) then
         e_kin = kinetic_energy(m, v, o%work)
         kc = kinetic_correction(o, m, a)
         call recoverable_energy(m, ms, u, e_links, e_cont)
         o%energy = energy_terms(o%e0, o%w_ext, e_kin, e_links, e_cont, o%e_links0, o%e_cont0, &
                                 o%d_damp, o%d_links, o%d_contact, o%d_impact, kc, o%ke_corr0)
         o%energy_balance_max = max(o%energy_balance_max, abs(o%energy(E_BALANCE)))
      end if
      if (recorded(o, k)) then
         call record(o, t, u(1:), v(1:), a(1:), pen, force, link_f, link_du, stat)
         if (stat /= MARTELLO_OK) then
            call observer_finish(o, t); return
         end if
      end if
      if (due) call check_divergence(o, t, e_kin + e_links + e_cont, u, v, stat)
      if (stat == MARTELLO_OK) call observer_watch(o, t, stat)
   end subroutine observer_sample_i8

   !> observer_sample with the grid point k as a default integer (the C door, k ≤ 2^31).
   subroutine observer_sample_i4(o, m, ms, t, u, v, a, pen, force, k, stat, link_f, link_du, &
                                 u_prev, v_prev, a_prev)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
      integer, intent(in) :: k
      integer, intent(out) :: stat
      real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
      call observer_sample_i8(o, m, ms, t, u, v, a, pen, force, int(k, i8), stat, link_f, &
                              link_du, u_prev, v_prev, a_prev)
   end subroutine observer_sample_i4

   !> The budget and the caller, after every accepted sample: max_steps (every sample),
   !> and every WATCH_EVERY samples the clock: max_wall, and the progress callback at most
   !> every PROGRESS_INTERVAL seconds (a non-zero return stops the run). stat:
   !> MARTELLO_ERR_LIMIT or MARTELLO_ERR_INTERRUPTED with the message, else unchanged.
   subroutine observer_watch(o, t, stat)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer, intent(inout) :: stat
      procedure(progress_callback), pointer :: report
      integer(i8) :: now
      real(dp) :: elapsed
      if (real(o%nsamples, dp) > o%max_steps) then
         write (o%message, '(a,a,es10.3,a,es12.5,a,es12.5,a)') integrator_name(o%kind), &
            ' took max_steps = ', o%max_steps, ' steps and reached t = ', t, ' s of t_end = ', &
            o%t_end, ' s: raise max_steps, or soften the scene (a stiffer contact or a lighter'// &
            ' mass needs more steps)'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      if (mod(o%nsamples, int(WATCH_EVERY, i8)) /= 0) return
      if (o%max_wall <= 0.0_dp .and. .not. c_associated(o%progress)) return
      call system_clock(now)
      elapsed = real(now - o%clock0, dp)/real(o%clock_rate, dp)
      if (o%max_wall > 0.0_dp .and. elapsed > o%max_wall) then
         write (o%message, '(a,a,es10.3,a,i0,a,es12.5,a,es12.5,a)') integrator_name(o%kind), &
            ' ran for max_wall = ', o%max_wall, ' s (', o%nsamples, ' steps) and reached t = ', &
            t, ' s of t_end = ', o%t_end, ' s: raise max_wall, or coarsen the run'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      if (.not. c_associated(o%progress)) return
      if (real(now - o%clock_last, dp) < PROGRESS_INTERVAL*real(o%clock_rate, dp)) return
      o%clock_last = now
      call c_f_procpointer(o%progress, report)
      if (report(o%progress_user, t, o%t_end, int(o%nsamples, c_long_long), elapsed) /= 0) then
         write (o%message, '(a,es12.5,a,i0,a)') 'interrupted at t = ', t, ' s (', o%nsamples, &
            ' steps)'
         stat = MARTELLO_ERR_INTERRUPTED
         call observer_finish(o, t)
      end if
   end subroutine observer_watch

   !> Divergence at time t, one rule for every integrator: a non-finite state or work, or
   !> the mechanical energy beyond divergence_factor·(e0 + Σ|ΔW_ext|), what the run was
   !> given (docs/integrators.md "divergence detection").
   subroutine check_divergence(o, t, e_mech, u, v, stat)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t, e_mech, u(0:), v(0:)
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (.not. (ieee_is_finite(e_mech) .and. all(ieee_is_finite(u)) .and. &
                 all(ieee_is_finite(v)) .and. &
                 ieee_is_finite(o%w_ext + o%d_damp + o%d_links + o%d_contact + o%d_impact))) then
         call observer_fail_nonfinite(o, t, stat)
      else if (-(o%energy(E_CONTACT) + o%energy(E_IMPACT)) > CREATED_BOUND*(o%e0 + o%w_abs) .and. &
               o%e0 + o%w_abs > 0.0_dp) then
         ! a passive contact only takes energy out: the realised restitution exceeds 1
         write (o%message, '(a,a,es12.5,a,es10.3,a,es10.3,a,a)') integrator_name(o%kind), &
            ' created energy at its contacts by t = ', t, ' s: ', &
            -(o%energy(E_CONTACT) + o%energy(E_IMPACT)), ' J, more than 1 % of the initial'// &
            ' energy + input work (', o%e0 + o%w_abs, ' J): a passive contact cannot'// &
            ' (restitution > 1); ', o%advice
         stat = MARTELLO_ERR_DIVERGED
         call observer_finish(o, t)
      else if (e_mech > o%divergence_factor*(o%e0 + o%w_abs) + tiny(1.0_dp) .and. &
               o%e0 + o%w_abs > 0.0_dp) then
         write (o%message, '(a,a,es12.5,a,es10.3,a,es10.3,a,a)') integrator_name(o%kind), &
            ' diverged at t = ', t, ' s: mechanical energy ', e_mech, ' J exceeds ', &
            o%divergence_factor*(o%e0 + o%w_abs), &
            ' J (divergence_factor x (initial energy + input work)); ', o%advice
         stat = MARTELLO_ERR_DIVERGED
         call observer_finish(o, t)
      end if
   end subroutine check_divergence

   !> A non-finite state, force or work at t (found here or by the method, e.g. in a
   !> right-hand side): the run has diverged.
   subroutine observer_fail_nonfinite(o, t, stat)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer, intent(out) :: stat
      write (o%message, '(a,a,es12.5,a)') integrator_name(o%kind), ' diverged at t = ', t, &
         ' s: non-finite state (NaN/inf)'
      stat = MARTELLO_ERR_DIVERGED
      call observer_finish(o, t)
   end subroutine observer_fail_nonfinite

   !> The method failed (code < 0) at t_reached, saying why. The results so far stay for
   !> diagnosis, open phases included (t_off = −1); they are not a result.
   subroutine observer_fail(o, code, t_reached, message, stat)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: code
      real(dp), intent(in) :: t_reached
      character(len=*), intent(in) :: message
      integer, intent(out) :: stat
      o%message = message
      stat = code
      call observer_finish(o, t_reached)
   end subroutine observer_fail

   !> The run stops at t_reached (the end, or a failure): phases still open become events
   !> with t_off = −1.
   subroutine observer_finish(o, t_reached)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t_reached
      integer :: c
      o%t_end_reached = t_reached
      do c = 1, size(o%ph_open)
         if (o%ph_open(c)) call observer_close_phase(o, c, -1.0_dp, 0.0_dp)
      end do
   end subroutine observer_finish

   !> Contact c starts a phase at t_on, approaching at v_in (δ̇ > 0).
   subroutine observer_open_phase(o, c, t_on, v_in)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t_on, v_in
      o%ph_open(c) = .true.
      o%ph_t(c) = t_on; o%ph_v(c) = v_in; o%ph_pen(c) = 0.0_dp; o%ph_f(c) = 0.0_dp
      o%impacts(c) = o%impacts(c) + 1
      call phase_change(o, c, t_on)
   end subroutine observer_open_phase

   !> Contact c ends its phase at t_off, leaving at v_out. pen, force: the contact's state at
   !> the sample that closes it, when the method decides the closing on that state (it then
   !> enters the phase maxima, as the states of the phase's other steps do).
   subroutine observer_close_phase(o, c, t_off, v_out, pen, force)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t_off, v_out
      real(dp), intent(in), optional :: pen, force
      if (present(pen)) o%ph_pen(c) = max(o%ph_pen(c), pen)
      if (present(force)) o%ph_f(c) = max(o%ph_f(c), force)
      call add_event(o, c, [o%ph_t(c), t_off, o%ph_v(c), v_out, o%ph_pen(c), o%ph_f(c)])
      o%ph_open(c) = .false.
      call phase_change(o, c, t_off)
   end subroutine observer_close_phase

   !> Contact c changed phase at t: its nodes' forces jump or kink there.
   subroutine phase_change(o, c, t)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t
      if (.not. allocated(o%con_nodes)) return
      o%node_change(o%con_nodes(:, c)) = max(o%node_change(o%con_nodes(:, c)), t)
   end subroutine phase_change

   !> An instantaneous phase of contact c at t (an impact resolved by an impulse): approach
   !> and separation speeds, penetration and force (or impulse) at the impact.
   subroutine observer_add_impact(o, c, t, v_in, v_out, pen, force)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t, v_in, v_out, pen, force
      call add_event(o, c, [t, t, v_in, v_out, pen, force])
      o%impacts(c) = o%impacts(c) + 1
      call phase_change(o, c, t)
   end subroutine observer_add_impact

   !> Phases of the penalty contacts of a fixed step (t − h, t], from the committed state
   !> ms: a contact that closed starts a phase at the onset located on the free side of the
   !> step by the quadratic δ + δ̇τ + ½δ̈τ² = 0 from the start (O(h³) in time, speed
   !> extrapolated likewise; one event of the method); one that opened ends it at the
   !> separation located likewise back from the end. un … the state at t − h, u … at t.
   subroutine observer_penalty_phases(o, m, ms, un, vn, an, u, v, a, t, h)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: un(0:), vn(0:), an(0:), u(0:), v(0:), a(0:), t, h
      integer :: c, ia, ib
      real(dp) :: d0, r0, q0, tau
      do c = 1, m%ncontact
         if (.not. ms%is_penalty(c)) cycle
         ia = m%con_a(c); ib = m%con_b(c)
         if (.not. o%ph_open(c) .and. ms%con_on(c)) then
            d0 = un(ia) - un(ib) - m%con_gap(c); r0 = vn(ia) - vn(ib); q0 = an(ia) - an(ib)
            tau = free_side_crossing(d0, r0, q0, 0.0_dp, h)
            call observer_open_phase(o, c, t - h + tau, r0 + q0*tau)
            o%counters(C_EVENTS) = o%counters(C_EVENTS) + 1_i8
         end if
         if (o%ph_open(c)) then
            o%ph_pen(c) = max(o%ph_pen(c), ms%con_pen(c)); o%ph_f(c) = max(o%ph_f(c), ms%con_f(c))
            if (.not. ms%con_on(c)) then
               d0 = u(ia) - u(ib) - m%con_gap(c); r0 = v(ia) - v(ib); q0 = a(ia) - a(ib)
               tau = free_side_crossing(d0, r0, q0, -h, 0.0_dp)
               call observer_close_phase(o, c, t + tau, r0 + q0*tau)
            end if
         end if
      end do
   end subroutine observer_penalty_phases

   !> Event location on the free side of a step: the first root of d + rate·τ + ½acc·τ² in
   !> [lo, hi] (O(h³) in time when the free motion is smooth); linear fallback, else hi.
   pure real(dp) function free_side_crossing(d, rate, acc, lo, hi) result(tau)
      real(dp), intent(in) :: d, rate, acc, lo, hi
      real(dp) :: disc, t1, t2, q
      tau = hi
      if (abs(acc) > 0.0_dp) then
         disc = rate*rate - 2.0_dp*acc*d
         if (disc >= 0.0_dp) then
            q = -0.5_dp*(rate + sign(sqrt(disc), rate))
            if (q /= 0.0_dp) then
               t1 = q/(0.5_dp*acc); t2 = d/q
            else
               t1 = 0.0_dp; t2 = 0.0_dp
            end if
            if (t1 >= lo .and. t1 <= hi .and. (t1 <= t2 .or. t2 < lo .or. t2 > hi)) then
               tau = t1; return
            end if
            if (t2 >= lo .and. t2 <= hi) then
               tau = t2; return
            end if
         end if
      end if
      if (rate /= 0.0_dp) then
         tau = -d/rate
         tau = min(max(tau, lo), hi)
      end if
   end function free_side_crossing

   !> The energy terms from the accumulated works (W, since t = 0) and recoverable energies:
   !> the dissipation of links (plasticity) and contacts is their work minus the change of
   !> their recoverable energy, so the balance is the work–energy identity
   !> KE0 + W_ext − KE − W_damp − W_links − W_contact − W_impact (≈ 0 to the method's accuracy).
   !> ke_corr, ke_corr0: a method's correction to ½vᵀMv in its conserved energy, now and at
   !> t = 0 (central difference; 0 for the others).
   pure function energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0) result(e)
      real(dp), intent(in) :: e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0
      real(dp) :: e(NENERGY)
      e = 0.0_dp
      e(E_KINETIC) = e_kin; e(E_RECOVERABLE) = e_links + e_cont; e(E_INPUT) = w_ext
      e(E_DAMPING) = d_damp
      e(E_PLASTIC) = d_links - (e_links - e_links0)
      e(E_CONTACT) = d_contact - (e_cont - e_cont0)
      e(E_INITIAL) = e0
      e(E_IMPACT) = d_impact
      e(E_BALANCE) = (e0 - ke_corr0) + w_ext - (e_kin - ke_corr) - e(E_RECOVERABLE) - e(E_DAMPING) &
                     - e(E_PLASTIC) - e(E_CONTACT) - e(E_IMPACT)
   end function energy_terms

   !> Append one history row (grows by doubling when a variable-step integrator needs it).
   !> stat = MARTELLO_ERR_MEMORY (message set) if the history cannot grow.
   subroutine record(r, t, u, v, a, pen, force, link_f, link_du, stat)
      class(results_t), intent(inout) :: r
      real(dp), intent(in) :: t, u(:), v(:), a(:), pen(:), force(:)
      real(dp), intent(in), optional :: link_f(:), link_du(:)   !< absent: NaN columns
      integer, intent(out) :: stat
      real(dp), allocatable :: tmp(:, :)
      integer :: k, c, nn, nc, nl, st
      stat = MARTELLO_OK
      if (r%nrec == size(r%hist, 2)) then
         allocate (tmp(r%ncol, 2*size(r%hist, 2)), stat=st)
         if (st /= 0) then
            write (r%message, '(a,i0,a,i0,a)') 'out of memory growing the history to ', &
               2*size(r%hist, 2), ' rows of ', r%ncol, ' columns: record less (output.every,'// &
               ' output.nodes, output.contacts)'
            stat = MARTELLO_ERR_MEMORY; return
         end if
         tmp(:, 1:r%nrec) = r%hist(:, 1:r%nrec)
         call move_alloc(tmp, r%hist)
      end if
      r%nrec = r%nrec + 1
      k = r%nrec; c = 1
      nn = size(r%out_nodes); nc = size(r%out_contacts); nl = size(r%out_links)
      r%hist(c, k) = t
      r%hist(c + 1:c + nn, k) = u(r%out_nodes); c = c + nn
      r%hist(c + 1:c + nn, k) = v(r%out_nodes); c = c + nn
      r%hist(c + 1:c + nn, k) = a(r%out_nodes); c = c + nn
      r%hist(c + 1:c + nc, k) = pen(r%out_contacts); c = c + nc
      r%hist(c + 1:c + nc, k) = force(r%out_contacts); c = c + nc
      if (present(link_f) .and. present(link_du)) then
         r%hist(c + 1:c + nl, k) = link_f(r%out_links); c = c + nl
         r%hist(c + 1:c + nl, k) = link_du(r%out_links); c = c + nl
      else
         r%hist(c + 1:c + 2*nl, k) = ieee_value(1.0_dp, ieee_quiet_nan)
         c = c + 2*nl
      end if
      r%hist(c + 1:c + NENERGY, k) = r%energy
   end subroutine record

   subroutine add_event(r, contact, values)
      class(results_t), intent(inout) :: r
      integer, intent(in) :: contact
      real(dp), intent(in) :: values(NEVENT)
      real(dp), allocatable :: tmp(:, :)
      integer, allocatable :: itmp(:)
      if (r%nevents == size(r%ev, 2)) then
         allocate (tmp(NEVENT, 2*size(r%ev, 2)), itmp(2*size(r%ev, 2)))
         tmp(:, 1:r%nevents) = r%ev(:, 1:r%nevents)
         itmp(1:r%nevents) = r%ev_contact(1:r%nevents)
         call move_alloc(tmp, r%ev); call move_alloc(itmp, r%ev_contact)
      end if
      r%nevents = r%nevents + 1
      r%ev(:, r%nevents) = values
      r%ev_contact(r%nevents) = contact
   end subroutine add_event

   !> Peaks over every accepted state: extremes of u, |v|, |a|, penetration and force; on the
   !> steps of a fixed-step method also the extrema inside them (hermite_extremum: u max,
   !> min, |u| and the largest local maximum u_peak; hermite_v_extremum; the parabola of |a|;
   !> contact_step_peaks, observer_link_step_extremum; docs/results.md). The adaptive
   !> methods hand theirs (observer_extremum, observer_peak).
   subroutine track(o, m, ms, t, u, v, a, pen, force, link_f, link_du, u_prev, v_prev, a_prev)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t, u(:), v(:), a(:), pen(:), force(:)
      real(dp), intent(in), optional :: link_f(:), link_du(:)
      real(dp), intent(in), optional :: u_prev(:), v_prev(:), a_prev(:)
      integer :: i
      real(dp) :: h
      logical :: stepped
      h = t - o%prev_t
      stepped = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. h > 0.0_dp
      if (present(u_prev)) then
         if (stepped) call a_parabolas()
         call peaks(u_prev, v_prev, a_prev)
      else
         call peaks(o%prev_u, o%prev_v, o%prev_a)
         o%prev_u = u; o%prev_v = v; o%prev_a = a
      end if
      ! the maxima are stored only when they change: a peak array is then read, not
      ! rewritten, at every step (these passes are a fair part of a chain step's memory traffic)
      do i = 1, size(pen)
         if (pen(i) > o%pen_max(i)) o%pen_max(i) = pen(i)
         if (force(i) > o%force_max(i)) o%force_max(i) = force(i)
      end do
      if (present(link_f) .and. present(link_du)) then
         do i = 1, size(link_f)
            call raise_to(o%link_force_absmax(i), abs(link_f(i)))
            call raise_to(o%link_du_absmax(i), abs(link_du(i)))
         end do
      end if
      if (stepped .and. present(u_prev)) then
         call contact_step_peaks(o, m, ms, o%prev_t, h, u_prev, v_prev, v, a, pen, force)
         if (present(link_f)) call observer_link_step_peaks(o, m, ms, h, u_prev, v_prev, a_prev, &
                                                            u, v, a, link_f)
      end if
      if (o%smooth_steps) o%chatter_prev = o%counters(C_CHATTER)
      o%prev_t = t
   contains
      subroutine peaks(un, vn, an)
         real(dp), intent(in) :: un(:), vn(:), an(:)
         associate (umax => o%u_max, umin => o%u_min, vmax => o%v_absmax, amax => o%a_absmax, &
                    upk => o%u_peak, tpk => o%t_peak)
            do i = 1, size(u)
               if (u(i) > umax(i)) umax(i) = u(i)
               if (u(i) < umin(i)) umin(i) = u(i)
               if (abs(v(i)) > vmax(i)) vmax(i) = abs(v(i))
               if (abs(a(i)) > amax(i)) then
                  amax(i) = abs(a(i))
                  ! a new sampled peak of |a|: located on the parabola through this sample,
                  ! the one before and the next (a_parabolas)
                  if (stepped) then
                     o%npend1 = o%npend1 + 1; o%pend1(o%npend1) = i
                     o%a_m1(i) = an(i); o%a_0(i) = a(i); o%a_gen(i) = o%nsamples
                  end if
               end if
               call fold_absmax(o, i, t, u(i))
               if (o%fixed_steps .and. o%prev_t >= 0.0_dp .and. h > 0.0_dp) then
                  call hermite_extremum(o, i, o%prev_t, h, un(i), vn(i), an(i), u(i), v(i), a(i))
                  call hermite_v_extremum(vmax(i), h, vn(i), an(i), v(i), a(i))
                  ! a maximum on the step's end
                  if (vn(i) > 0.0_dp .and. v(i) == 0.0_dp .and. u(i) > upk(i)) then
                     upk(i) = u(i); tpk(i) = t
                  end if
               end if
            end do
         end associate
      end subroutine peaks

      !> The peak of |a| between the samples: a sample k that raised it (a candidate) is the
      !> middle of the parabola through k − 1, k, k + 1, whose vertex (equal steps; inside
      !> the middle step when the middle sample is the largest) is O(h³) in a, below the O(h²)
      !> of the steps, if a is smooth there: no jump of the forces (a phase change of a
      !> contact at the node, a chatter resolution, a kink of a load) from k − 1 to k + 2,
      !> and no kink — the second differences at k and k + 1 agree to half their size (a slope
      !> kink at the peak, as a bilinear spring's yield onto a flat line, makes them differ by
      !> O(h); its vertex would overshoot by O(h)). Candidates of sample k are completed here
      !> at k + 1 (a_p1) and decided at k + 2.
      subroutine a_parabolas()
         integer :: k, j
         real(dp) :: ym, y0, yp, yq, d2, sg
         logical :: smooth
         if (o%npend2 > 0) then
            smooth = o%counters(C_CHATTER) == o%pend2_stamp .and. load_breakpoint(m, o%pend2_t0) > t
            do k = 1, o%npend2
               j = o%pend2(k)
               if (.not. smooth .or. o%a_gen(j) /= o%nsamples - 2 .or. o%node_change(j) > o%pend2_t0) cycle
               sg = sign(1.0_dp, o%a_0(j))
               ym = sg*o%a_m1(j); y0 = sg*o%a_0(j); yp = sg*o%a_p1(j); yq = sg*a(j)
               d2 = ym - 2.0_dp*y0 + yp
               if (.not. (y0 >= ym .and. y0 >= yp .and. d2 < 0.0_dp)) cycle
               if (abs((y0 - 2.0_dp*yp + yq) - d2) > 0.5_dp*abs(d2)) cycle
               o%a_absmax(j) = max(o%a_absmax(j), y0 - (yp - ym)**2/(8.0_dp*d2))
            end do
         end if
         ! the last sample's candidates, completed with this one's a
         do k = 1, o%npend1
            j = o%pend1(k)
            o%pend2(k) = j
            if (o%a_gen(j) == o%nsamples - 1) o%a_p1(j) = a(j)
         end do
         o%npend2 = o%npend1; o%pend2_t0 = o%pend1_t0; o%pend2_stamp = o%pend1_stamp
         o%npend1 = 0; o%pend1_t0 = o%prev_t; o%pend1_stamp = o%chatter_prev
      end subroutine a_parabolas
   end subroutine track

   !> x(i) of a node array on 1..n, 0 for the ground (i = 0)
   pure real(dp) function nodal(x, i)
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: i
      nodal = 0.0_dp
      if (i > 0) nodal = x(i)
   end function nodal

   !> x ← max(x, y), the NaN x starts from replaced without comparing it (an ordered
   !> comparison with a NaN raises the invalid flag: a trap under -ffpe-trap=invalid)
   pure subroutine raise_to(x, y)
      real(dp), intent(inout) :: x
      real(dp), intent(in) :: y
      if (ieee_is_nan(x)) then
         x = y
      else if (x < y) then
         x = y
      end if
   end subroutine raise_to

   !> The peaks of the penalty contacts inside a fixed step [t0, t0 + h] from (un, vn) to
   !> (v, a; δ in pen) (nodes 1..n), while the contact's phase spans the whole step: δ on the cubic
   !> Hermite of (δ, δ̇) at both ends, the force on the cubic Hermite of (P, Ṗ) with
   !> Ṗ = P_δ δ̇ + P_δ̇ δ̈ from the law's tangents (contact_force) where the law pushes at both
   !> ends (a contact held open by the chatter rule, or a clipped Kelvin past its cut-off,
   !> does not). O(h⁴) in the value where the law is smooth over the step (docs/results.md).
   subroutine contact_step_peaks(o, m, ms, t0, h, un, vn, v, a, pen, force)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t0, h, un(:), vn(:), v(:), a(:), pen(:), force(:)
      integer :: c, ia, ib
      real(dp) :: d0, r0, r1, q1, f, dfd, dfv, fr1
      do c = 1, m%ncontact
         if (.not. (pen(c) > 0.0_dp)) cycle
         if (.not. ms%is_penalty(c)) cycle
         ia = m%con_a(c); ib = m%con_b(c)
         r1 = nodal(v, ia) - nodal(v, ib); q1 = nodal(a, ia) - nodal(a, ib)
         ! the law's tangents (the linear and Kelvin ones in line: a chain's every step)
         select case (m%con_law(c))
         case (LAW_LINEAR, LAW_KELVIN)
            fr1 = 0.0_dp
            if (force(c) > 0.0_dp) fr1 = o%c_k(c)*r1 + o%c_c(c)*q1
         case default
            call contact_force(m%con_law(c), m%con_par(:, c), m%con_mstar(c), pen(c), r1, &
                               ms%con_vin(c), f, dfd, dfv)
            fr1 = dfd*r1 + dfv*q1
         end select
         d0 = nodal(un, ia) - nodal(un, ib) - m%con_gap(c)
         if (d0 > 0.0_dp .and. o%ph_open(c) .and. o%ph_t(c) <= t0) then
            r0 = nodal(vn, ia) - nodal(vn, ib)
            call fold_hermite_max(h, d0, r0, pen(c), r1, o%pen_max(c), o%ph_pen(c))
            if (o%c_prev_f(c) > 0.0_dp .and. force(c) > 0.0_dp) &
               call fold_hermite_max(h, o%c_prev_f(c), o%c_prev_fr(c), force(c), fr1, &
                                     o%force_max(c), o%ph_f(c))
         end if
         o%c_prev_f(c) = force(c); o%c_prev_fr(c) = fr1
      end do
   end subroutine contact_step_peaks

   !> The largest value inside a step of the cubic Hermite of (q, q̇) at both ends (q0, r0 at
   !> the start, q1, r1 at the end, a step of h) where the rate turns from > 0 to < 0, into
   !> both running maxima x and y.
   pure subroutine fold_hermite_max(h, q0, r0, q1, r1, x, y)
      real(dp), intent(in) :: h, q0, r0, q1, r1
      real(dp), intent(inout) :: x, y
      real(dp) :: s(2), p(2)
      integer :: k
      if (.not. (r0 > 0.0_dp .and. r1 < 0.0_dp)) return
      call cubic_hermite_extrema(h, q0, r0, q1, r1, s, p)
      do k = 1, 2
         if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
         x = max(x, p(k)); y = max(y, p(k))
      end do
   end subroutine fold_hermite_max

   !> The peaks of link j inside a fixed step of h, from the relative motion of its nodes at
   !> both ends (du, du̇, dü) and its force f1 at the end (docs/results.md). The elongation on
   !> the cubic Hermite of (du, du̇) where du̇ changes sign. The force of a spring, a bar or a
   !> bilinear spring is monotone in du along a stretch where du is (its tangent is k or ρk
   !> ≥ 0), so its extremum is at the one of du, du*: valued f1 + k(du* − du1), exact for
   !> these piecewise-linear laws (after a turn the link unloads elastically, with k, up to
   !> the step's end). A dashpot's or a fluid damper's force is monotone in du̇: its extremum
   !> is at that of du̇, on the cubic Hermite of (du̇, dü) where dü changes sign, valued by
   !> the law. The public door of the fused chain step, which tracks its link peaks itself.
   subroutine observer_link_step_extremum(o, m, j, h, du0, dv0, da0, du1, dv1, da1, f1)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: h, du0, dv0, da0, du1, dv1, da1, f1
      real(dp) :: s(2), p(2), f, kt, ct, fnew
      integer :: k
      if (dv0*dv1 < 0.0_dp) then
         call cubic_hermite_extrema(h, du0, dv0, du1, dv1, s, p)
         do k = 1, 2
            if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
            call raise_to(o%link_du_absmax(j), abs(p(k)))
            select case (m%link_kind(j))
            case (LINK_SPRING, LINK_BAR, LINK_BILINEAR)
               call raise_to(o%link_force_absmax(j), abs(f1 + m%link_par(L_STIFF, j)*(p(k) - du1)))
            end select
         end do
      end if
      select case (m%link_kind(j))
      case (LINK_DASHPOT, LINK_FLUID_DAMPER)
         if (.not. (da0*da1 < 0.0_dp)) return
         call cubic_hermite_extrema(h, dv0, da0, dv1, da1, s, p)
         do k = 1, 2
            if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
            call link_force(m%link_kind(j), m%link_par(:, j), du1, p(k), 0.0_dp, du1, f, kt, ct, &
                            fnew)
            call raise_to(o%link_force_absmax(j), abs(f))
         end do
      end select
   end subroutine observer_link_step_extremum

   !> The peaks of every link inside a fixed step of h from (un, vn, an) to (u, v, a) (nodes
   !> 1..n; observer_link_step_extremum). f1: the link forces at the step's end; absent, the
   !> law's for springs and bars and the committed ms%link_f for bilinear springs (what the
   !> fused chain step keeps between its recorded samples; a damper's is not needed).
   subroutine observer_link_step_peaks(o, m, ms, h, un, vn, an, u, v, a, f1)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: h, un(:), vn(:), an(:), u(:), v(:), a(:)
      real(dp), intent(in), optional :: f1(:)
      integer :: j, ia, ib
      real(dp) :: du1, dv0, dv1, f
      logical :: damper
      do j = 1, m%nlink
         ia = m%link_a(j); ib = m%link_b(j)
         ! only a step where du̇ (or, for a damper, dü) changes sign holds a peak
         dv0 = nodal(vn, ia) - nodal(vn, ib); dv1 = nodal(v, ia) - nodal(v, ib)
         damper = m%link_kind(j) == LINK_DASHPOT .or. m%link_kind(j) == LINK_FLUID_DAMPER
         if (.not. (dv0*dv1 < 0.0_dp)) then
            if (.not. damper) cycle
            if (.not. ((nodal(an, ia) - nodal(an, ib))*(nodal(a, ia) - nodal(a, ib)) < 0.0_dp)) cycle
         end if
         du1 = nodal(u, ia) - nodal(u, ib)
         if (present(f1)) then
            f = f1(j)
         else if (m%link_kind(j) == LINK_BILINEAR) then
            f = ms%link_f(j)
         else
            f = m%link_par(L_STIFF, j)*du1
         end if
         call observer_link_step_extremum(o, m, j, h, nodal(un, ia) - nodal(un, ib), dv0, &
                                          nodal(an, ia) - nodal(an, ib), du1, dv1, &
                                          nodal(a, ia) - nodal(a, ib), f)
      end do
   end subroutine observer_link_step_peaks

   !> A peak of kind (PEAK_*) of item j (node, contact or link) located by the method inside
   !> an accepted step, with value q (signed: |q| enters the node and link peaks; δ and the
   !> contact force their maxima and those of the open phase).
   subroutine observer_peak(o, kind, j, q)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: kind, j
      real(dp), intent(in) :: q
      select case (kind)
      case (PEAK_V)
         o%v_absmax(j) = max(o%v_absmax(j), abs(q))
      case (PEAK_A)
         o%a_absmax(j) = max(o%a_absmax(j), abs(q))
      case (PEAK_PEN)
         o%pen_max(j) = max(o%pen_max(j), q)
         if (o%ph_open(j)) o%ph_pen(j) = max(o%ph_pen(j), q)
      case (PEAK_FORCE)
         o%force_max(j) = max(o%force_max(j), q)
         if (o%ph_open(j)) o%ph_f(j) = max(o%ph_f(j), q)
      case (PEAK_LINK_FORCE)
         call raise_to(o%link_force_absmax(j), abs(q))
      case (PEAK_LINK_DU)
         call raise_to(o%link_du_absmax(j), abs(q))
      end select
   end subroutine observer_peak

   !> The value a located peak of kind, j must exceed to change what is reported: the open
   !> phase's maximum for δ and the contact force (the run's otherwise), the run's peak for
   !> the others (|·|; 0 for a link not yet tracked).
   real(dp) function observer_peak_value(o, kind, j) result(q)
      type(observer_t), intent(in) :: o
      integer, intent(in) :: kind, j
      q = 0.0_dp
      select case (kind)
      case (PEAK_V)
         q = o%v_absmax(j)
      case (PEAK_A)
         q = o%a_absmax(j)
      case (PEAK_PEN)
         q = o%pen_max(j)
         if (o%ph_open(j)) q = o%ph_pen(j)
      case (PEAK_FORCE)
         q = o%force_max(j)
         if (o%ph_open(j)) q = o%ph_f(j)
      case (PEAK_LINK_FORCE)
         if (.not. ieee_is_nan(o%link_force_absmax(j))) q = o%link_force_absmax(j)
      case (PEAK_LINK_DU)
         if (.not. ieee_is_nan(o%link_du_absmax(j))) q = o%link_du_absmax(j)
      end select
   end function observer_peak_value

   !> The number of items of a peak kind (0 for an unknown kind).
   pure integer function peak_items(o, kind) result(n)
      type(observer_t), intent(in) :: o
      integer, intent(in) :: kind
      select case (kind)
      case (PEAK_V, PEAK_A)
         n = size(o%v_absmax)
      case (PEAK_PEN, PEAK_FORCE)
         n = size(o%pen_max)
      case (PEAK_LINK_FORCE, PEAK_LINK_DU)
         n = size(o%link_force_absmax)
      case default
         n = 0
      end select
   end function peak_items

   !> An extremum of node i's displacement located by the method inside an accepted step, at t
   !> with value u (the root of the node's velocity on the stepper's own solution,
   !> docs/run-layer.md): folded into u_max, u_min, and for a maximum (maximum = .true.) into
   !> u_peak, t_peak.
   subroutine observer_extremum(o, i, t, u, maximum)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: i
      real(dp), intent(in) :: t, u
      logical, intent(in) :: maximum
      o%u_max(i) = max(o%u_max(i), u); o%u_min(i) = min(o%u_min(i), u)
      call fold_absmax(o, i, t, u)
      if (maximum .and. u > o%u_peak(i)) then
         o%u_peak(i) = u; o%t_peak(i) = t
      end if
   end subroutine observer_extremum

   !> u_absmax(i), t_absmax(i) ← |u|, t where |u| is larger
   subroutine fold_absmax(o, i, t, u)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: i
      real(dp), intent(in) :: t, u
      if (abs(u) > o%u_absmax(i)) then
         o%u_absmax(i) = abs(u); o%t_absmax(i) = t
      end if
   end subroutine fold_absmax

   !> The extremum of u inside a fixed step [t0, t0 + h], located on the cubic Hermite
   !> interpolant of (u, v) at both ends, p(s) = u0 H00 + h v0 H10 + u1 H01 + h v1 H11
   !> (s = τ/h): the root of p'(s), a quadratic, where v changes sign inside the step; into
   !> u_max, u_min, u_absmax and, a maximum, u_peak.
   !> Interpolation error O(h⁴) in u (O(h³) in the time of the extremum), below the
   !> O(h²) of the structural steps themselves (docs/results.md). A turn the step's
   !> accelerations do not support (v reversed by an impulse: no a of the turn's sign at
   !> either end) is not a smooth extremum and is left to the step values.
   subroutine hermite_extremum(o, i, t0, h, u0, v0, a0, u1, v1, a1)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: i
      real(dp), intent(in) :: t0, h, u0, v0, a0, u1, v1, a1
      real(dp) :: s(2), p(2)
      integer :: k
      if (.not. (v0*v1 < 0.0_dp)) return
      if (v0 > 0.0_dp .and. min(a0, a1) >= 0.0_dp) return
      if (v0 < 0.0_dp .and. max(a0, a1) <= 0.0_dp) return
      call cubic_hermite_extrema(h, u0, v0, u1, v1, s, p)
      do k = 1, 2
         if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
         call fold_absmax(o, i, t0 + s(k)*h, p(k))
         o%u_max(i) = max(o%u_max(i), p(k)); o%u_min(i) = min(o%u_min(i), p(k))
         if (v0 > 0.0_dp .and. p(k) > o%u_peak(i)) then      ! a local maximum
            o%u_peak(i) = p(k); o%t_peak(i) = t0 + s(k)*h
         end if
      end do
   end subroutine hermite_extremum

   !> |v| at the extremum of v inside a fixed step, on the cubic Hermite of (v, a) at both
   !> ends, where a changes sign inside the step (O(h⁴) in v; docs/results.md): into vmax.
   subroutine hermite_v_extremum(vmax, h, v0, a0, v1, a1)
      real(dp), intent(inout) :: vmax
      real(dp), intent(in) :: h, v0, a0, v1, a1
      real(dp) :: s(2), p(2)
      integer :: k
      if (.not. (a0*a1 < 0.0_dp)) return
      call cubic_hermite_extrema(h, v0, a0, v1, a1, s, p)
      do k = 1, 2
         if (s(k) > 0.0_dp .and. s(k) < 1.0_dp) vmax = max(vmax, abs(p(k)))
      end do
   end subroutine hermite_v_extremum

   !> The stationary points s (in units of h; outside (0, 1) if none) and values p of the
   !> cubic Hermite interpolant of y with derivative d at both ends of a step of length h.
   pure subroutine cubic_hermite_extrema(h, u0, v0, u1, v1, s, p)
      real(dp), intent(in) :: h, u0, v0, u1, v1
      real(dp), intent(out) :: s(2), p(2)
      real(dp) :: qa, qb, qc, disc, r(2), x
      integer :: k
      ! p'(s) = qa s² + qb s + qc, from H00' = 6s² − 6s, H10' = 3s² − 4s + 1,
      ! H01' = −6s² + 6s, H11' = 3s² − 2s
      qa = 6.0_dp*(u0 - u1) + 3.0_dp*h*(v0 + v1)
      qb = -6.0_dp*(u0 - u1) - h*(4.0_dp*v0 + 2.0_dp*v1)
      qc = h*v0
      if (abs(qa) <= epsilon(1.0_dp)*(abs(qb) + abs(qc))) then
         r = -qc/qb
      else
         disc = max(qb*qb - 4.0_dp*qa*qc, 0.0_dp)
         ! the cancellation-free pair of roots
         r(1) = -0.5_dp*(qb + sign(sqrt(disc), qb))/qa
         r(2) = qc/(qa*r(1))
      end if
      do k = 1, 2
         x = r(k); s(k) = x; p(k) = 0.0_dp
         if (.not. (x > 0.0_dp .and. x < 1.0_dp)) cycle   ! (no cube of a far root: overflow)
         p(k) = u0*(2.0_dp*x**3 - 3.0_dp*x**2 + 1.0_dp) + h*v0*(x**3 - 2.0_dp*x**2 + x) + &
                u1*(-2.0_dp*x**3 + 3.0_dp*x**2) + h*v1*(x**3 - x**2)
      end do
   end subroutine cubic_hermite_extrema
end module martello_observer
