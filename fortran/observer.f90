!> The observer of a dynamic run (docs/run-layer.md): the history and its recording
!> cadence, contact phases, peaks, the energy balance, divergence detection, the counters
!> and the final message, for every integrator. The methods (martello_fixed_step's steppers,
!> the C integrators through c/martello_internal.h) hand it accepted states, work
!> increments and the phase changes they locate. results_t is what a finished run exposes
!> (martello_api_results); observer_t adds the working state of the measurement.
module martello_observer
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_element_rows, only: rows_t, row_dot, row_dot1, row_lo, row_hi
   use martello_assembly, only: mech_state_t, kinetic_energy, recoverable_energy, mass_times, &
      load_breakpoint
   use martello_links, only: link_force, LINK_SPRING, LINK_BAR, LINK_BILINEAR, LINK_DASHPOT, &
      LINK_FLUID_DAMPER, L_STIFF, NPAR_LINK
   use martello_contact_laws, only: contact_force, LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING
   use martello_integrator_settings, only: integrator_settings_t, integrator_name
   use martello_run_quantities
   use martello_registry, only: INTEGRATORS, TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, &
      TRACK_CONTACT_PEAKS, TRACK_PHASES, TRACK_ALL
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite, ieee_is_nan
   use, intrinsic :: iso_c_binding, only: c_funptr, c_ptr, c_null_funptr, c_null_ptr, &
      c_associated, c_f_procpointer, c_int, c_double, c_long_long
   implicit none
   private
   public :: results_t, observer_t, observer_init, observer_begin, observer_sample, observer_failed, &
      observer_work, observer_open_phase, observer_close_phase, observer_add_impact, &
      observer_penalty_phases, observer_fail, observer_fail_nonfinite, observer_finish, &
      free_side_crossing, progress_callback, observer_extremum, observer_recorded, &
      observer_node_peaks, observer_contact_peaks, observer_phase_peaks, observer_phase_change, &
      observer_energy_due, observer_phase_lists, observer_events, tracks, TRACK_NODE_PEAKS, &
      TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS, TRACK_PHASES, TRACK_ALL, &
      observer_peak, observer_peak_value, peak_items, observer_link_step_extremum, &
      observer_step_max, observer_step_absmax, observer_a_parabolas, observer_a_candidate, &
      observer_contact_step_peaks, raise_to, observer_node_samples, observer_node_turns, &
      observer_node_step_extrema, PEAK_V, PEAK_A, PEAK_PEN, PEAK_FORCE, PEAK_LINK_FORCE, PEAK_LINK_DU, &
      NCOUNTERS, C_STEPS, C_REJECTED, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS, &
      C_JACOBIANS, C_ROOT_EVALS, C_CHATTER, NENERGY, E_KINETIC, E_RECOVERABLE, E_INPUT, E_DAMPING, &
      E_PLASTIC, E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT, NEVENT, EV_T_ON, EV_T_OFF, &
      EV_V_IN, EV_V_OUT, EV_MAX_PEN, EV_MAX_FORCE

   type :: results_t
      !> what the run tracks (TRACK_* bits, martello_run_set_tracking): the arrays of what it
      !> does not track have no entries (the accessors give NaN), its phases no rows;
      !> impacts are always counted
      integer :: tracking = TRACK_ALL
      integer :: n_nodes = 0, n_contacts = 0, n_links = 0
      ! history: hist(:, k) = [t, (u, v, a of each output node), (δ, P of each output
      ! contact), (force, elongation of each output link), energy(1:NENERGY)]
      integer :: ncol = 0, nrec = 0
      !> a failure met where no status could be returned (the event table could not grow):
      !> the next history row returns it (record), the last grid point's at the latest
      integer :: deferred_stat = MARTELLO_OK
      real(dp), allocatable :: hist(:, :)
      integer, allocatable :: out_nodes(:), out_contacts(:), out_links(:)
      ! events: one per contact phase
      integer :: nevents = 0
      integer, allocatable :: ev_contact(:)
      real(dp), allocatable :: ev(:, :)
      ! peaks over every accepted step and located inside the steps (docs/results.md): the
      ! adaptive methods hand theirs (observer_extremum, observer_peak), the fixed-step ones
      ! are located on each step's polynomial (observer_node_peaks and the step routines)
      real(dp), allocatable :: u_max(:), u_min(:), v_absmax(:), a_absmax(:)
      !> the largest local maximum of u (u_peak at t_peak)
      real(dp), allocatable :: u_peak(:), t_peak(:)
      !> the largest |u| and its time
      real(dp), allocatable :: u_absmax(:), t_absmax(:)
      !> a fixed-step method: the extrema of u and v are located on each step's cubic Hermite
      !> (hermite_extremum, observer_step_absmax)
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
      !> past observer_phase_lists' number of contacts, a contact not listed in full keeps its
      !> first and last phase alone, outside the event table: ph_kept(c) is how many of them
      !> it has (0, 1, 2), LISTED for a contact whose every phase is a row. The first is
      !> ev_first(:, c); the last is ph_t, ph_toff, ph_v, ph_vout, ph_pen, ph_f (the open
      !> phase's state, which a closed phase leaves there). Not allocated: every phase is a row.
      integer, allocatable :: ph_kept(:)
      real(dp), allocatable :: ev_first(:, :), ph_toff(:), ph_vout(:)
      !> the time of the previous sample (< 0: none yet)
      real(dp) :: prev_t = -1.0_dp
      real(dp), allocatable :: work(:)          !< scratch (0:n): M v (observer_begin)
      !> a C integrator's accelerations (0:n), contact penetrations and forces (allocated by
      !> martello_observer_begin, martello_api_internal)
      real(dp), allocatable :: acc(:), c_pen(:), c_force(:)
      !> the fixed-step method's states lie on one smooth motion between the phase changes
      !> (not Moreau–Jean's velocity jumps): the peaks of a, δ, the contact and link forces
      !> and elongations are located on its steps
      logical :: smooth_steps = .false.
      !> per node (0:n): the time of the last phase change (onset, separation, impact) of a
      !> contact at it; the chatter resolutions at the previous sample (the jumps of the
      !> forces a located peak of |a| must not straddle). con_rows: the contacts' rows
      !> (their nodes), for the phase changes the method does not name them at (the fused
      !> chain step does)
      real(dp), allocatable :: node_change(:)
      type(rows_t) :: con_rows
      logical :: has_con_rows = .false.
      integer(i8) :: chatter_prev = 0_i8
      !> per contact, for the general fixed-step path: its force and force rate at the
      !> previous sample (the fused chain step computes them again from its previous state)
      real(dp), allocatable :: c_prev_f(:), c_prev_fr(:)
      !> the peak of |a| on fixed steps (observer_a_parabolas): a sample k that raised it
      !> waits two samples for the parabola through k − 1, k, k + 1 and the smoothness test
      !> with k + 2. Per node: a at k − 1, k, k + 1 and the sample k of its latest candidate
      !> modulo 256 (a_gen; the lists name the candidates of the last three samples at most,
      !> so no two stamps in use are equal); the candidates of the last two samples (pend1:
      !> k = the last, pend2: the one before), with the time and the chatter count of their
      !> sample k − 1
      real(dp), allocatable :: a_m1(:), a_0(:), a_p1(:)
      integer(int8), allocatable :: a_gen(:)
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
   !> The fix of the out-of-memory line for the history and the phase list of a run.
   character(len=*), parameter :: FIX_RECORD_LESS = &
      'record less (output.every, output.nodes, output.contacts)', &
      FIX_FEWER_PHASES = 'track fewer contact phases (analysis.output.track) or use a smaller scene'
   !> ph_kept of a contact whose phases are all rows
   integer, parameter :: LISTED = -huge(1)

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
                            n_links, out_links, stat, tracking)
      type(observer_t), intent(inout) :: o
      type(integrator_settings_t), intent(in) :: s
      integer, intent(in) :: n_nodes, n_contacts, out_nodes(:), out_contacts(:), capacity, &
                             n_links, out_links(:)
      integer, intent(out) :: stat
      integer, intent(in), optional :: tracking
      type(observer_t) :: fresh
      real(dp) :: steps
      integer :: st, nn, nl, ncp, nph, rows
      character(len=96) :: what
      o = fresh        ! every field at its default, every array deallocated
      stat = MARTELLO_OK
      if (present(tracking)) o%tracking = tracking
      o%n_nodes = n_nodes; o%n_contacts = n_contacts; o%n_links = n_links
      ! the arrays of what the run does not track have no entries
      nn = merge(n_nodes, 0, tracks(o, TRACK_NODE_PEAKS))
      nl = merge(n_links, 0, tracks(o, TRACK_LINK_PEAKS))
      ncp = merge(n_contacts, 0, tracks(o, TRACK_CONTACT_PEAKS))
      nph = merge(n_contacts, 0, tracks(o, TRACK_PHASES))
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
         stat = MARTELLO_ERR_LIMIT
         steps = 1.0_dp
      end if
      o%n_grid = ceiling(steps, i8)
      o%out_nodes = out_nodes; o%out_contacts = out_contacts; o%out_links = out_links
      o%ncol = 1 + 3*size(out_nodes) + 2*size(out_contacts) + 2*size(out_links) + NENERGY
      rows = max(min(capacity, HIST_START), 2)
      allocate (o%hist(o%ncol, rows), stat=st)
      if (st /= 0) then
         write (what, '(a,i0,a,i0,a)') 'the history of a run (', rows, ' rows of ', o%ncol, ' columns)'
         call out_of_memory(trim(what), REAL_BYTES*o%ncol*real(rows, dp), FIX_RECORD_LESS, stat, &
                            o%message)
         return
      end if
      allocate (o%ev(NEVENT, 16), o%ev_contact(16), &
                o%u_max(nn), o%u_min(nn), o%v_absmax(nn), o%a_absmax(nn), &
                o%pen_max(ncp), o%force_max(ncp), o%impacts(n_contacts), &
                o%u_peak(nn), o%t_peak(nn), o%link_force_absmax(nl), &
                o%u_absmax(nn), o%t_absmax(nn), &
                o%link_du_absmax(nl), o%ph_open(n_contacts), &
                o%ph_t(nph), o%ph_v(nph), o%ph_pen(nph), o%ph_f(nph), &
                stat=st)
      if (st /= 0) then
         write (what, '(a,i0,a,i0,a,i0,a)') 'the results of a run of ', n_nodes, ' nodes, ', &
            n_contacts, ' contacts and ', n_links, ' links'
         call out_of_memory(trim(what), REAL_BYTES*(10.0_dp*nn + 2.0_dp*ncp + 4.0_dp*nph &
                            + 2.0_dp*nl + NEVENT*16) + INT_BYTES*(n_contacts + 16.0_dp) &
                            + storage_size(o%ph_open)/8*real(n_contacts, dp), FIX_SMALLER_SCENE, &
                            stat, o%message)
         return
      end if
      ! NaN until a state is tracked (a run that fails before its first step)
      o%link_force_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      o%link_du_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      o%u_peak = -huge(1.0_dp); o%t_peak = -1.0_dp
      o%u_absmax = -1.0_dp; o%t_absmax = -1.0_dp
      o%u_max = -huge(1.0_dp); o%u_min = huge(1.0_dp); o%v_absmax = 0.0_dp
      o%a_absmax = 0.0_dp; o%pen_max = -huge(1.0_dp); o%force_max = 0.0_dp; o%impacts = 0
      o%ph_open = .false.
   end subroutine observer_init

   !> The state at t = 0, before its first sample: the initial energies the balance starts
   !> from, and a phase opened at t = 0 for every penalty contact closed there. energy_interval: samples between energy evaluations (the strategy's choice: 16
   !> for cheap fixed steps, 1 for adaptive ones); advice ends a divergence message;
   !> ke_aMa: the method conserves ½vᵀMv − ke_aMa·aᵀMa (Verlet; 0 for the others).
   !> energies = [kinetic, links, contacts]: a method that keeps its own element states (no
   !> ms, the fused chain step) hands them, and has opened the phases at t = 0 itself.
   !> The observer's working arrays are allocated here, none later: stat =
   !> MARTELLO_ERR_MEMORY (o%message its line) if they cannot be.
   subroutine observer_begin(o, m, ms, u, v, a, energy_interval, advice, ke_aMa, stat, energies)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: u(0:), v(0:), a(0:)
      integer, intent(in) :: energy_interval
      character(len=*), intent(in) :: advice
      real(dp), intent(in) :: ke_aMa
      integer, intent(out) :: stat
      real(dp), intent(in), optional :: energies(3)
      real(dp) :: e_kin
      integer :: c
      character(len=64) :: what
      call located_peak_state(o, m%n, present(energies), stat)
      ! the scratch vector of the energies this observer evaluates itself (kinetic_correction:
      ! ke_aMa /= 0)
      if (stat == 0 .and. .not. allocated(o%work) .and. (.not. present(energies) .or. ke_aMa /= 0.0_dp)) &
         allocate (o%work(0:m%n), stat=stat)
      if (stat /= 0) then
         write (what, '(a,i0,a)') 'the working state of the results of a run of ', m%n, ' nodes'
         call out_of_memory(trim(what), REAL_BYTES*(8.0_dp*m%n + 2.0_dp*size(o%ph_open) + 2), &
                            FIX_SMALLER_SCENE, stat, o%message)
         return
      end if
      if (present(energies)) then
         e_kin = energies(1); o%e_links0 = energies(2); o%e_cont0 = energies(3)
      else
         if (o%smooth_steps) then
            o%con_rows = m%con; o%has_con_rows = .true.
         end if
         do c = 1, m%ncontact
            if (ms%con_on(c)) call observer_open_phase(o, c, 0.0_dp, row_dot(m%con, c, v))
            ! the force and its rate the first step's located peaks start from
            if (allocated(o%c_prev_f)) &
               call contact_force_rate(m, ms, c, row_dot(m%con, c, v), &
                                       row_dot(m%con, c, a), o%c_prev_f(c), o%c_prev_fr(c))
         end do
         e_kin = kinetic_energy(m, v, o%work)
         call recoverable_energy(m, ms, u, o%e_links0, o%e_cont0)
      end if
      o%e0 = e_kin + o%e_links0 + o%e_cont0
      o%ke_aMa = ke_aMa
      ! the balance starts from the method's conserved energy e0 − ke_corr
      o%ke_corr0 = o%e0 - (o%e0 - kinetic_correction(o, m, a))
      o%energy_interval = max(energy_interval, 1)
      o%advice = advice
   end subroutine observer_begin

   !> The working state of the located peaks of a smooth fixed-step method (smooth_steps):
   !> the phase change times per node and the candidates of |a| where node peaks are
   !> tracked, and, for a method that measures through observer_sample (not folded: the
   !> general path), the contact forces and rates at the previous sample where a contact
   !> peak or phase is tracked.
   subroutine located_peak_state(o, n, folded, st)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: n
      logical, intent(in) :: folded
      integer, intent(out) :: st
      integer :: nn, nc
      st = 0
      if (.not. o%smooth_steps) return
      nn = merge(n, 0, tracks(o, TRACK_NODE_PEAKS))
      allocate (o%node_change(0:nn), o%a_m1(nn), o%a_0(nn), o%a_p1(nn), o%a_gen(nn), &
                o%pend1(nn), o%pend2(nn), stat=st)
      if (st /= 0) return
      o%node_change = -huge(1.0_dp)
      if (folded .or. .not. (tracks(o, TRACK_CONTACT_PEAKS) .or. tracks(o, TRACK_PHASES))) return
      nc = size(o%ph_open)
      allocate (o%c_prev_f(nc), o%c_prev_fr(nc), source=0.0_dp, stat=st)
   end subroutine located_peak_state

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

   !> Whether the next sample, at grid point k, evaluates the energy terms: where recorded,
   !> every energy_interval-th sample and once a work is not finite (a method that hands
   !> its energies to observer_sample computes them then).
   logical function observer_energy_due(o, k) result(due)
      type(observer_t), intent(in) :: o
      integer(i8), intent(in) :: k
      due = recorded(o, k) .or. mod(o%nsamples + 1, int(o%energy_interval, i8)) == 0 .or. &
            .not. ieee_is_finite(o%w_last + o%d_damp + o%d_links + o%d_contact + o%d_impact)
   end function observer_energy_due

   !> An accepted state at t (once per accepted step and at t = 0, after the step's phase
   !> changes): phase maxima and peaks; the energy terms and the divergence test where
   !> recorded, every energy_interval-th sample and once a work is not finite; a history row
   !> where recorded. k: the grid point t = k·dt of the state, or −1. u, v, a on nodes 0:n;
   !> u_prev … the previous state if the method keeps it (saves a copy). stat:
   !> MARTELLO_ERR_DIVERGED, with the message, when the run must stop.
   !> folded: the method has measured this state item by item in its own sweeps, the
   !> extrema inside the step included (observer_a_parabolas, observer_node_peaks,
   !> observer_a_candidate, observer_contact_step_peaks, observer_phase_change,
   !> observer_phase_peaks, observer_contact_peaks, the link peaks: the fused chain step);
   !> pen, force (and link_f, link_du) then serve the history row alone, and are read only
   !> where recorded.
   !> energies = [kinetic, links, contacts] at this state, from such a method where
   !> observer_energy_due (it keeps no ms).
   subroutine observer_sample_i8(o, m, ms, t, u, v, a, pen, force, k, stat, link_f, link_du, &
                                 u_prev, v_prev, a_prev, folded, energies)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
      integer(i8), intent(in) :: k
      integer, intent(out) :: stat
      real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
      logical, intent(in), optional :: folded
      real(dp), intent(in), optional :: energies(3)
      real(dp) :: e_kin, e_links, e_cont, kc
      logical :: due, measured
      stat = MARTELLO_OK
      due = observer_energy_due(o, k)
      o%nsamples = o%nsamples + 1
      measured = .false.
      if (present(folded)) measured = folded
      if (.not. measured) then
         if (tracks(o, TRACK_PHASES)) &
            call observer_phase_peaks(o%ph_open(1:size(pen)), pen, force, o%ph_pen(1:size(pen)), &
                                      o%ph_f(1:size(pen)))
         if (tracks(o, TRACK_CONTACT_PEAKS)) &
            call observer_contact_peaks(pen, force, o%pen_max(1:size(pen)), o%force_max(1:size(pen)))
         call track(o, m, t, u(1:), v(1:), a(1:), link_f, link_du, u_prev, v_prev, a_prev)
      end if
      ! the next step's start
      if (o%smooth_steps) o%chatter_prev = o%counters(C_CHATTER)
      o%prev_t = t
      if (due) then
         if (present(energies)) then
            e_kin = energies(1); e_links = energies(2); e_cont = energies(3)
         else
            e_kin = kinetic_energy(m, v, o%work)
            call recoverable_energy(m, ms, u, e_links, e_cont)
         end if
         kc = kinetic_correction(o, m, a)
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
                                 u_prev, v_prev, a_prev, folded, energies)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
      integer, intent(in) :: k
      integer, intent(out) :: stat
      real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
      logical, intent(in), optional :: folded
      real(dp), intent(in), optional :: energies(3)
      call observer_sample_i8(o, m, ms, t, u, v, a, pen, force, int(k, i8), stat, link_f, &
                              link_du, u_prev, v_prev, a_prev, folded, energies)
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

   !> The run failed at t with code, o%message already saying why (memory running out): the
   !> observer's failure path, as every other failure takes it.
   subroutine observer_failed(o, t, code)
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer, intent(inout) :: code
      character(len=len(o%message)) :: msg
      integer :: failed
      msg = o%message; failed = code
      call observer_fail(o, failed, t, msg, code)
   end subroutine observer_failed

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
      o%impacts(c) = o%impacts(c) + 1
      call phase_change(o, c, t_on)
      if (.not. tracks(o, TRACK_PHASES)) return
      o%ph_t(c) = t_on; o%ph_v(c) = v_in; o%ph_pen(c) = 0.0_dp; o%ph_f(c) = 0.0_dp
   end subroutine observer_open_phase

   !> Contact c ends its phase at t_off, leaving at v_out. pen, force: the contact's state at
   !> the sample that closes it, when the method decides the closing on that state (it then
   !> enters the phase maxima, as the states of the phase's other steps do).
   subroutine observer_close_phase(o, c, t_off, v_out, pen, force)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t_off, v_out
      real(dp), intent(in), optional :: pen, force
      o%ph_open(c) = .false.
      call phase_change(o, c, t_off)
      if (.not. tracks(o, TRACK_PHASES)) return
      if (present(pen)) o%ph_pen(c) = max(o%ph_pen(c), pen)
      if (present(force)) o%ph_f(c) = max(o%ph_f(c), force)
      call keep_event(o, c, [o%ph_t(c), t_off, o%ph_v(c), v_out, o%ph_pen(c), o%ph_f(c)])
   end subroutine observer_close_phase

   !> An instantaneous phase of contact c at t (an impact resolved by an impulse): approach
   !> and separation speeds, penetration and force (or impulse) at the impact.
   subroutine observer_add_impact(o, c, t, v_in, v_out, pen, force)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t, v_in, v_out, pen, force
      if (tracks(o, TRACK_PHASES)) call keep_event(o, c, [t, t, v_in, v_out, pen, force])
      o%impacts(c) = o%impacts(c) + 1
      call phase_change(o, c, t)
   end subroutine observer_add_impact

   !> Contact c changed phase at t: its nodes' forces jump or kink there (node_change, read
   !> by observer_a_parabolas). nodes: the contact's, where the method names them (the
   !> fused chain step keeps no table of them); else con_nodes.
   subroutine phase_change(o, c, t, nodes)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: t
      integer, intent(in), optional :: nodes(2)
      integer :: k, j
      if (.not. allocated(o%node_change)) return
      if (size(o%node_change) < 2) return           ! node peaks not tracked
      if (present(nodes)) then
         do k = 1, 2
            j = nodes(k)
            o%node_change(j) = max(o%node_change(j), t)
         end do
      else if (o%has_con_rows) then
         do k = row_lo(o%con_rows, c), row_hi(o%con_rows, c)
            j = o%con_rows%node(k)
            o%node_change(j) = max(o%node_change(j), t)
         end do
      end if
   end subroutine phase_change

   !> Phases of the penalty contacts of a fixed step (t − h, t], from the committed state
   !> ms: a contact that closed starts a phase at the onset located on the free side of the
   !> step by the quadratic δ + δ̇τ + ½δ̈τ² = 0 from the start (O(h³) in time, speed
   !> extrapolated likewise; one event of the method); one that opened ends it at the
   !> separation located likewise back from the end. un … the state at t − h, u … at t.
   !> On a smooth method's step (smooth_steps), a phase spanning the step also has its
   !> maxima located inside it (observer_step_max).
   subroutine observer_penalty_phases(o, m, ms, un, vn, an, u, v, a, t, h)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      real(dp), intent(in) :: un(0:), vn(0:), an(0:), u(0:), v(0:), a(0:), t, h
      integer :: c
      real(dp) :: f, fr
      logical :: located
      located = allocated(o%c_prev_f) .and. o%prev_t >= 0.0_dp .and. t > o%prev_t
      do c = 1, m%ncontact
         if (.not. ms%is_penalty(c)) cycle
         if (located) then
            call contact_force_rate(m, ms, c, row_dot(m%con, c, v), row_dot(m%con, c, a), f, fr)
            call observer_contact_step_peaks(o, c, o%ph_open(c) .and. ms%con_on(c), t - o%prev_t, &
                                       row_dot(m%con, c, un) - m%con_gap(c), row_dot(m%con, c, vn), &
                                       o%c_prev_f(c), o%c_prev_fr(c), ms%con_pen(c), &
                                       row_dot(m%con, c, v), f, fr)
            o%c_prev_f(c) = f; o%c_prev_fr(c) = fr
         end if
         if (ms%con_on(c) .neqv. o%ph_open(c)) &
            call observer_phase_change(o, c, ms%con_on(c), ms%con_pen(c), ms%con_f(c), &
                                       row_dot(m%con, c, un) - m%con_gap(c), row_dot(m%con, c, vn), &
                                       row_dot(m%con, c, an), row_dot(m%con, c, u) - m%con_gap(c), &
                                       row_dot(m%con, c, v), row_dot(m%con, c, a), t, h)
         if (tracks(o, TRACK_PHASES)) call observer_phase_peaks(o%ph_open(c), ms%con_pen(c), &
                                                               ms%con_f(c), o%ph_pen(c), o%ph_f(c))
      end do
   end subroutine observer_penalty_phases

   !> The force f of penalty contact c of the committed state ms and its rate
   !> Ṗ = P_δ δ̇ + P_δ̇ δ̈ from the law's tangents (the linear and Kelvin laws in line), at
   !> the rates r = δ̇, q = δ̈ (0 where the contact does not push).
   subroutine contact_force_rate(m, ms, c, r, q, f, fr)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: ms
      integer, intent(in) :: c
      real(dp), intent(in) :: r, q
      real(dp), intent(out) :: f, fr
      real(dp) :: fl, dfd, dfv
      f = ms%con_f(c); fr = 0.0_dp
      if (.not. (f > 0.0_dp .and. ms%con_pen(c) > 0.0_dp)) return
      select case (m%con_law(c))
      case (LAW_LINEAR)
         fr = m%con_par(P_STIFF, c)*r
      case (LAW_KELVIN)
         fr = m%con_par(P_STIFF, c)*r + m%con_par(P_DAMPING, c)*q
      case default
         call contact_force(m%con_law(c), m%con_par(:, c), m%con_mstar(c), ms%con_pen(c), r, &
                            ms%con_vin(c), fl, dfd, dfv)
         fr = dfd*r + dfv*q
      end select
   end subroutine contact_force_rate

   !> The maxima of penalty contact c located inside a smooth fixed step of h (the one
   !> procedure of the general path and the fused chain step), while its phase spans the
   !> step (spans: open at both ends, the phase change of the step not yet handed over) and
   !> δ > 0 at both ends: δ on the cubic Hermite of (δ, δ̇) from (d0, r0) to (d1, r1), the
   !> force on that of (P, Ṗ) from (f0, fr0) to (f1, fr1) where the law pushes at both ends
   !> (a clipped Kelvin past its cut-off, or a contact the chatter rule holds open, does
   !> not). O(h⁴) in the value where the law is smooth over the step (docs/results.md).
   !> Into the run's and the phase's maxima, as tracked.
   subroutine observer_contact_step_peaks(o, c, spans, h, d0, r0, f0, fr0, d1, r1, f1, fr1)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      logical, intent(in) :: spans
      real(dp), intent(in) :: h, d0, r0, f0, fr0, d1, r1, f1, fr1
      real(dp) :: dm, fm
      if (.not. (spans .and. d0 > 0.0_dp .and. d1 > 0.0_dp)) return
      dm = observer_step_max(h, d0, r0, d1, r1)
      fm = -huge(1.0_dp)
      if (f0 > 0.0_dp .and. f1 > 0.0_dp) fm = observer_step_max(h, f0, fr0, f1, fr1)
      if (tracks(o, TRACK_CONTACT_PEAKS)) call observer_contact_peaks(dm, fm, o%pen_max(c), &
                                                                      o%force_max(c))
      if (tracks(o, TRACK_PHASES)) call observer_phase_peaks(.true., dm, fm, o%ph_pen(c), o%ph_f(c))
   end subroutine observer_contact_step_peaks

   !> Penalty contact c opens (on) or closes (not on) in the fixed step (t − h, t], its
   !> phase being closed or open: a phase starts at the onset located on the free side of the
   !> step by the quadratic δ + δ̇τ + ½δ̈τ² = 0 from the start (O(h³) in time, speed
   !> extrapolated likewise; one event of the method), or ends, its maxima taken with the
   !> contact's state at t (pen, force), at the separation located likewise back from the
   !> end. d0, r0, q0 and d1, r1, q1: δ, δ̇, δ̈ at t − h and at t. A method that measures its
   !> contacts in its own sweep (the fused chain step) calls this where on differs from
   !> o%ph_open(c) (after observer_contact_step_peaks), then observer_phase_peaks and
   !> observer_contact_peaks; nodes: the contact's, which it names (phase_change).
   subroutine observer_phase_change(o, c, on, pen, force, d0, r0, q0, d1, r1, q1, t, h, nodes)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      logical, intent(in) :: on
      real(dp), intent(in) :: pen, force, d0, r0, q0, d1, r1, q1, t, h
      integer, intent(in), optional :: nodes(2)
      real(dp) :: tau
      if (on) then
         tau = free_side_crossing(d0, r0, q0, 0.0_dp, h)
         call observer_open_phase(o, c, t - h + tau, r0 + q0*tau)
         o%counters(C_EVENTS) = o%counters(C_EVENTS) + 1_i8
         if (present(nodes)) call phase_change(o, c, t - h + tau, nodes)
      else
         tau = free_side_crossing(d1, r1, q1, -h, 0.0_dp)
         call observer_close_phase(o, c, t + tau, r1 + q1*tau, pen, force)
         if (present(nodes)) call phase_change(o, c, t + tau, nodes)
      end if
   end subroutine observer_phase_change

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
      character(len=96) :: what
      stat = r%deferred_stat
      if (stat /= MARTELLO_OK) return
      if (r%nrec == size(r%hist, 2)) then
         allocate (tmp(r%ncol, 2*size(r%hist, 2)), stat=st)
         if (st /= 0) then
            write (what, '(a,i0,a,i0,a)') 'the history of a run grown to ', 2*size(r%hist, 2), &
               ' rows of ', r%ncol, ' columns'
            call out_of_memory(trim(what), REAL_BYTES*r%ncol*2.0_dp*size(r%hist, 2), &
                               FIX_RECORD_LESS, stat, r%message)
            return
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

   !> Which contacts keep every phase (docs/results.md): all of them while the scene has at
   !> most max_contacts contacts (max_contacts < 0: always); past it, the history's output
   !> contacts, and the others their first and last phase alone (keep_event). After
   !> observer_init.
   subroutine observer_phase_lists(o, max_contacts, stat)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: max_contacts
      integer, intent(out) :: stat
      integer :: nc
      character(len=64) :: what
      stat = MARTELLO_OK
      if (allocated(o%ph_kept)) deallocate (o%ph_kept, o%ev_first, o%ph_toff, o%ph_vout)
      nc = size(o%ph_open)
      if (max_contacts < 0 .or. nc <= max_contacts .or. .not. tracks(o, TRACK_PHASES)) return
      allocate (o%ph_kept(nc), o%ev_first(NEVENT, nc), o%ph_toff(nc), o%ph_vout(nc), stat=stat)
      if (stat /= 0) then
         write (what, '(a,i0,a)') 'the first and last phases of ', nc, ' contacts'
         call out_of_memory(trim(what), ((NEVENT + 2)*REAL_BYTES + INT_BYTES)*real(nc, dp), &
                            FIX_FEWER_PHASES, stat, o%message)
         return
      end if
      o%ph_kept = 0
      o%ph_kept(o%out_contacts) = LISTED
   end subroutine observer_phase_lists

   !> A phase of contact c ends: an event row, or for a contact that keeps its first and
   !> last phase alone (observer_phase_lists), its first phase, then its last one, in place.
   subroutine keep_event(o, c, values)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: c
      real(dp), intent(in) :: values(NEVENT)
      if (.not. allocated(o%ph_kept)) then
         call add_event(o, c, values); return
      end if
      select case (o%ph_kept(c))
      case (LISTED)
         call add_event(o, c, values)
      case (0)
         o%ev_first(:, c) = values; o%ph_kept(c) = 1
      case default
         o%ph_t(c) = values(EV_T_ON); o%ph_toff(c) = values(EV_T_OFF)
         o%ph_v(c) = values(EV_V_IN); o%ph_vout(c) = values(EV_V_OUT)
         o%ph_pen(c) = values(EV_MAX_PEN); o%ph_f(c) = values(EV_MAX_FORCE)
         o%ph_kept(c) = 2
      end select
   end subroutine keep_event

   !> The contact phases a finished run lists (martello_run_events): the rows of the event
   !> table, then the first and last phase of each contact that keeps them alone
   !> (observer_phase_lists). n: their number; contact (0-based) and values filled when
   !> present.
   subroutine observer_events(o, n, contact, values)
      type(observer_t), intent(in) :: o
      integer, intent(out) :: n
      integer, intent(out), optional :: contact(:)
      real(dp), intent(out), optional :: values(:, :)
      integer :: c
      n = o%nevents
      if (present(contact)) contact(1:n) = o%ev_contact(1:n) - 1
      if (present(values)) values(:, 1:n) = o%ev(:, 1:n)
      if (.not. allocated(o%ph_kept)) return
      do c = 1, size(o%ph_kept)
         if (o%ph_kept(c) == LISTED .or. o%ph_kept(c) == 0) cycle
         n = n + 1
         if (present(contact)) contact(n) = c - 1
         if (present(values)) values(:, n) = o%ev_first(:, c)
         if (o%ph_kept(c) < 2) cycle
         n = n + 1
         if (present(contact)) contact(n) = c - 1
         if (present(values)) values(:, n) = [o%ph_t(c), o%ph_toff(c), o%ph_v(c), o%ph_vout(c), &
                                              o%ph_pen(c), o%ph_f(c)]
      end do
   end subroutine observer_events

   subroutine add_event(r, contact, values)
      class(results_t), intent(inout) :: r
      integer, intent(in) :: contact
      real(dp), intent(in) :: values(NEVENT)
      real(dp), allocatable :: tmp(:, :)
      integer, allocatable :: itmp(:)
      integer :: st
      character(len=64) :: what
      if (r%nevents == size(r%ev, 2)) then
         allocate (tmp(NEVENT, 2*size(r%ev, 2)), itmp(2*size(r%ev, 2)), stat=st)
         if (st /= 0) then
            ! the phase is lost; the run fails at its next history row (deferred_stat)
            write (what, '(a,i0,a)') 'the contact phases of a run grown to ', 2*size(r%ev, 2), ' rows'
            if (r%deferred_stat == MARTELLO_OK) &
               call out_of_memory(trim(what), (NEVENT*REAL_BYTES + INT_BYTES)*2.0_dp*size(r%ev, 2), &
                                  FIX_FEWER_PHASES, r%deferred_stat, r%message)
            return
         end if
         tmp(:, 1:r%nevents) = r%ev(:, 1:r%nevents)
         itmp(1:r%nevents) = r%ev_contact(1:r%nevents)
         call move_alloc(tmp, r%ev); call move_alloc(itmp, r%ev_contact)
      end if
      r%nevents = r%nevents + 1
      r%ev(:, r%nevents) = values
      r%ev_contact(r%nevents) = contact
   end subroutine add_event

   !> Peaks over every accepted state (after the step's phase changes): the node peaks
   !> (observer_node_peaks) and, when the link states are given, the link peaks; on the
   !> steps of a fixed-step method given the previous state (u_prev …) also the extrema inside
   !> them: of u and v on every fixed step, of |a| (observer_a_parabolas) and of the links
   !> (link_step_peaks) on a smooth one (docs/results.md). The contact maxima inside the
   !> steps are observer_penalty_phases'. The adaptive methods hand theirs
   !> (observer_extremum, observer_peak).
   subroutine track(o, m, t, u, v, a, link_f, link_du, u_prev, v_prev, a_prev)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t, u(:), v(:), a(:)
      real(dp), intent(in), optional :: link_f(:), link_du(:)
      real(dp), intent(in), optional :: u_prev(:), v_prev(:), a_prev(:)
      integer :: i
      logical :: stepped, raised
      stepped = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. t > o%prev_t .and. present(u_prev)
      if (.not. tracks(o, TRACK_NODE_PEAKS)) then
         ! nothing of the nodes
      else if (present(u_prev)) then
         if (stepped) call observer_a_parabolas(o, m, t, a, o%nsamples)
         do i = 1, size(u)
            call observer_node_peaks(t, o%prev_t, o%fixed_steps, u_prev(i), v_prev(i), a_prev(i), &
                                     u(i), v(i), a(i), o%u_max(i), o%u_min(i), o%v_absmax(i), &
                                     o%a_absmax(i), o%u_absmax(i), o%t_absmax(i), o%u_peak(i), &
                                     o%t_peak(i), raised)
            if (raised .and. stepped) call observer_a_candidate(o, i, a_prev(i), a(i), o%nsamples)
         end do
      else
         ! no previous state (an adaptive method, which locates its own): the samples alone
         do i = 1, size(u)
            call observer_node_peaks(t, -1.0_dp, .false., u(i), v(i), a(i), u(i), v(i), a(i), &
                                     o%u_max(i), o%u_min(i), o%v_absmax(i), o%a_absmax(i), &
                                     o%u_absmax(i), o%t_absmax(i), o%u_peak(i), o%t_peak(i), raised)
         end do
      end if
      if (present(link_f) .and. present(link_du) .and. tracks(o, TRACK_LINK_PEAKS)) then
         do i = 1, size(link_f)
            call raise_to(o%link_force_absmax(i), abs(link_f(i)))
            call raise_to(o%link_du_absmax(i), abs(link_du(i)))
         end do
         if (stepped) call link_step_peaks(o, m, t - o%prev_t, u_prev, v_prev, a_prev, u, v, a, &
                                           link_f)
      end if
   end subroutine track


   !> x ← max(x, y), the NaN x starts from replaced without comparing it (an ordered
   !> comparison with a NaN raises the invalid flag: a trap under -ffpe-trap=invalid)
   elemental subroutine raise_to(x, y)
      real(dp), intent(inout) :: x
      real(dp), intent(in) :: y
      if (ieee_is_nan(x)) then
         x = y
      else if (x < y) then
         x = y
      end if
   end subroutine raise_to

   !> The peaks of every link inside a smooth fixed step of h from (un, vn, an) to (u, v, a)
   !> (nodes 1..n), f1 the link forces at its end (observer_link_step_extremum): only a step
   !> where du̇ (or, for a damper, dü) changes sign holds one.
   subroutine link_step_peaks(o, m, h, un, vn, an, u, v, a, f1)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: h, un(:), vn(:), an(:), u(:), v(:), a(:), f1(:)
      integer :: j
      real(dp) :: dv0, dv1, da0, da1
      logical :: damper
      do j = 1, m%nlink
         dv0 = row_dot1(m%lnk, j, vn); dv1 = row_dot1(m%lnk, j, v)
         damper = m%link_kind(j) == LINK_DASHPOT .or. m%link_kind(j) == LINK_FLUID_DAMPER
         da0 = 0.0_dp; da1 = 0.0_dp
         if (damper) then
            da0 = row_dot1(m%lnk, j, an); da1 = row_dot1(m%lnk, j, a)
         end if
         if (.not. (dv0*dv1 < 0.0_dp .or. da0*da1 < 0.0_dp)) cycle
         call observer_link_step_extremum(m%link_kind(j), m%link_par(:, j), h, &
                                          row_dot1(m%lnk, j, un), dv0, da0, &
                                          row_dot1(m%lnk, j, u), dv1, da1, f1(j), &
                                          o%link_force_absmax(j), o%link_du_absmax(j))
      end do
   end subroutine link_step_peaks

   !> The peaks of a link (kind, its parameters par) inside a smooth fixed step of h, from
   !> the relative motion of its nodes at both ends (du, du̇, dü) and its force f1 at the end
   !> (docs/results.md), into its running maxima of |force| (fmax) and |elongation| (dmax).
   !> The elongation on the cubic Hermite of (du, du̇) where du̇ changes sign. The force of a
   !> spring, a bar or a bilinear spring is monotone in du along a stretch where du is (its
   !> tangent is k or ρk ≥ 0), so its extremum is at the one of du, du*: valued by the law,
   !> k du* for a spring or a bar, f1 + k(du* − du1) for a bilinear spring (after a turn it
   !> unloads elastically, with k, up to the step's end; exact for these piecewise-linear
   !> laws). A dashpot's or a fluid damper's force is monotone in du̇: its extremum is at
   !> that of du̇, on the cubic Hermite of (du̇, dü) where dü changes sign, valued by the law.
   !> The general path calls it for every link, the fused chain step for its bilinear ones
   !> (its linear ones: observer_step_absmax per node and pair, the same numbers).
   pure subroutine observer_link_step_extremum(kind, par, h, du0, dv0, da0, du1, dv1, da1, f1, &
                                               fmax, dmax)
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_LINK), h, du0, dv0, da0, du1, dv1, da1, f1
      real(dp), intent(inout) :: fmax, dmax
      real(dp) :: s(2), p(2), f, kt, ct, fnew
      integer :: k
      if (dv0*dv1 < 0.0_dp) then
         call cubic_hermite_extrema(h, du0, dv0, du1, dv1, s, p)
         do k = 1, 2
            if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
            call raise_to(dmax, abs(p(k)))
            select case (kind)
            case (LINK_SPRING, LINK_BAR)
               call raise_to(fmax, abs(par(L_STIFF)*p(k)))
            case (LINK_BILINEAR)
               call raise_to(fmax, abs(f1 + par(L_STIFF)*(p(k) - du1)))
            end select
         end do
      end if
      select case (kind)
      case (LINK_DASHPOT, LINK_FLUID_DAMPER)
         if (.not. (da0*da1 < 0.0_dp)) return
         call cubic_hermite_extrema(h, dv0, da0, dv1, da1, s, p)
         do k = 1, 2
            if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
            call link_force(kind, par, du1, p(k), 0.0_dp, du1, f, kt, ct, fnew)
            call raise_to(fmax, abs(f))
         end do
      end select
   end subroutine observer_link_step_extremum

   !> The largest value inside a step of h of the cubic Hermite of (q, q̇) at both ends (q0,
   !> r0 at the start, q1, r1 at the end) where the rate turns from > 0 to < 0; −huge where
   !> none (a contact's δ and force: observer_contact_step_peaks).
   elemental real(dp) function observer_step_max(h, q0, r0, q1, r1) result(x)
      real(dp), intent(in) :: h, q0, r0, q1, r1
      real(dp) :: s(2), p(2)
      integer :: k
      x = -huge(1.0_dp)
      if (.not. (r0 > 0.0_dp .and. r1 < 0.0_dp)) return
      call cubic_hermite_extrema(h, q0, r0, q1, r1, s, p)
      do k = 1, 2
         if (s(k) > 0.0_dp .and. s(k) < 1.0_dp) x = max(x, p(k))
      end do
   end function observer_step_max

   !> The largest |value| inside a step of h of the cubic Hermite of (q, q̇) at both ends
   !> where the rate changes sign; 0 where none (a link's elongation, a dashpot's rate: the
   !> fused chain step's per node and pair maxima, as observer_link_step_extremum).
   elemental real(dp) function observer_step_absmax(h, q0, r0, q1, r1) result(x)
      real(dp), intent(in) :: h, q0, r0, q1, r1
      real(dp) :: s(2), p(2)
      integer :: k
      x = 0.0_dp
      if (.not. (r0*r1 < 0.0_dp)) return
      call cubic_hermite_extrema(h, q0, r0, q1, r1, s, p)
      do k = 1, 2
         if (s(k) > 0.0_dp .and. s(k) < 1.0_dp) x = max(x, abs(p(k)))
      end do
   end function observer_step_absmax

   !> The peak of |a| between the samples of a smooth fixed-step method, at sample number
   !> sample (t, a on nodes 1..n; before the sample's candidates, observer_a_candidate): a
   !> sample k that raised it (a candidate) is the middle of the parabola through k − 1, k,
   !> k + 1, whose vertex (equal steps; inside the middle step when the middle sample is the
   !> largest) is O(h³) in a, below the O(h²) of the steps, if a is smooth there: no jump of
   !> the forces (a phase change of a contact at the node, a chatter resolution, a kink of a
   !> load) from k − 1 to k + 2, and no kink — the second differences at k and k + 1 agree to
   !> half their size (a slope kink at the peak, as a bilinear spring's yield onto a flat
   !> line, makes them differ by O(h); its vertex would overshoot by O(h)). Candidates of
   !> sample k are completed here at k + 1 (a_p1) and decided at k + 2.
   subroutine observer_a_parabolas(o, m, t, a, sample)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t, a(:)
      integer(i8), intent(in) :: sample
      integer :: k, j
      integer(int8) :: s2, s1
      real(dp) :: ym, y0, yp, yq, d2, sg
      logical :: smooth
      s2 = stamp(sample - 2); s1 = stamp(sample - 1)
      if (o%npend2 > 0) then
         smooth = o%counters(C_CHATTER) == o%pend2_stamp .and. load_breakpoint(m, o%pend2_t0) > t
         do k = 1, o%npend2
            j = o%pend2(k)
            if (.not. smooth .or. o%a_gen(j) /= s2 .or. o%node_change(j) > o%pend2_t0) cycle
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
         if (o%a_gen(j) == s1) o%a_p1(j) = a(j)
      end do
      o%npend2 = o%npend1; o%pend2_t0 = o%pend1_t0; o%pend2_stamp = o%pend1_stamp
      o%npend1 = 0; o%pend1_t0 = o%prev_t; o%pend1_stamp = o%chatter_prev
   end subroutine observer_a_parabolas

   !> Node j raised its sampled peak of |a| at sample number sample of a smooth fixed-step
   !> method (observer_node_peaks' raised), from a_prev at the sample before to a_now: a
   !> candidate of observer_a_parabolas.
   subroutine observer_a_candidate(o, j, a_prev, a_now, sample)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: j
      real(dp), intent(in) :: a_prev, a_now
      integer(i8), intent(in) :: sample
      o%npend1 = o%npend1 + 1; o%pend1(o%npend1) = j
      o%a_m1(j) = a_prev; o%a_0(j) = a_now; o%a_gen(j) = stamp(sample)
   end subroutine observer_a_candidate

   !> A sample number modulo 256, as a_gen keeps it
   pure integer(int8) function stamp(sample)
      integer(i8), intent(in) :: sample
      stamp = int(modulo(sample, 256_i8) - 128_i8, int8)
   end function stamp

   !> The peaks of a node at the accepted state (u, v, a) at t, the previous one (un, vn, an)
   !> at the last sample's time t_prev (< 0: none): extremes of u, |v|, |a| (umax … amax) and
   !> the largest |u| and its time (uabs, tabs) at the state; for a fixed-step method also
   !> the extrema of u and v located on the step's cubic Hermite (into the same and into the
   !> largest local maximum of u, upk at tpk: hermite_extremum, observer_step_absmax). raised:
   !> the state raised amax (a candidate of observer_a_parabolas on a smooth method). The
   !> maxima are stored only when they change: a peak array is then read, not rewritten, at
   !> every step (a fair part of a chain step's memory traffic). Elemental: track calls it
   !> on every node; a method that measures its nodes in its own sweep (the fused chain step)
   !> node by node, on the observer's arrays, before its folded observer_sample.
   elemental subroutine observer_node_peaks(t, t_prev, fixed_steps, un, vn, an, u, v, a, umax, &
                                            umin, vmax, amax, uabs, tabs, upk, tpk, raised)
      real(dp), intent(in) :: t, t_prev, un, vn, an, u, v, a
      logical, intent(in) :: fixed_steps
      real(dp), intent(inout) :: umax, umin, vmax, amax, uabs, tabs, upk, tpk
      logical, intent(out) :: raised
      call observer_node_samples(t, u, v, a, umax, umin, vmax, amax, uabs, tabs, raised)
      if (.not. fixed_steps) return
      if (observer_node_turns(vn, an, v, a)) &
         call observer_node_step_extrema(t, t_prev, un, vn, an, u, v, a, umax, umin, vmax, uabs, &
                                         tabs, upk, tpk)
   end subroutine observer_node_peaks

   !> observer_node_peaks at the state: extremes of u, |v|, |a| and the largest |u| at t;
   !> raised: the state raised amax. (The method that measures itself calls the three parts of
   !> observer_node_peaks, so that this, the part of every node and step, is compiled into
   !> its loop.)
   elemental subroutine observer_node_samples(t, u, v, a, umax, umin, vmax, amax, uabs, tabs, &
                                              raised)
      real(dp), intent(in) :: t, u, v, a
      real(dp), intent(inout) :: umax, umin, vmax, amax, uabs, tabs
      logical, intent(out) :: raised
      if (u > umax) umax = u
      if (u < umin) umin = u
      if (abs(v) > vmax) vmax = abs(v)
      raised = abs(a) > amax
      if (raised) amax = abs(a)
      call raise_absmax(uabs, tabs, t, u)
   end subroutine observer_node_samples

   !> Whether a fixed step from (vn, an) to (v, a) can hold an extremum of u (v changes sign,
   !> or reaches 0 from above) or of v (a changes sign): most steps of most nodes hold none.
   elemental logical function observer_node_turns(vn, an, v, a) result(turns)
      real(dp), intent(in) :: vn, an, v, a
      turns = vn*v < 0.0_dp .or. an*a < 0.0_dp .or. (vn > 0.0_dp .and. v == 0.0_dp)
   end function observer_node_turns

   !> observer_node_peaks inside a fixed step from the state (un, vn, an) at t_prev to
   !> (u, v, a) at t where observer_node_turns (t_prev < 0: no step yet): the extrema of u
   !> and v on the step's cubic Hermite (hermite_extremum, observer_step_absmax), and a maximum
   !> of u on the step's end.
   elemental subroutine observer_node_step_extrema(t, t_prev, un, vn, an, u, v, a, umax, umin, &
                                                   vmax, uabs, tabs, upk, tpk)
      real(dp), intent(in) :: t, t_prev, un, vn, an, u, v, a
      real(dp), intent(inout) :: umax, umin, vmax, uabs, tabs, upk, tpk
      real(dp) :: h
      h = t - t_prev
      if (.not. (t_prev >= 0.0_dp .and. h > 0.0_dp)) return
      call hermite_extremum(t_prev, h, un, vn, an, u, v, a, umax, umin, uabs, tabs, upk, tpk)
      ! |v| at the extremum of v, on the cubic Hermite of (v, a) where a changes sign
      ! (O(h⁴) in v; docs/results.md)
      vmax = max(vmax, observer_step_absmax(h, vn, an, v, a))
      ! a maximum on the step's end
      if (vn > 0.0_dp .and. v == 0.0_dp .and. u > upk) then
         upk = u; tpk = t
      end if
   end subroutine observer_node_step_extrema

   !> The maxima of a contact at a sample: its largest δ and force (pen_max, force_max).
   !> Elemental: observer_sample calls it on every contact; a method that measures its
   !> contacts in its own sweep, contact by contact, on the observer's arrays.
   elemental subroutine observer_contact_peaks(pen, force, pen_max, force_max)
      real(dp), intent(in) :: pen, force
      real(dp), intent(inout) :: pen_max, force_max
      if (pen > pen_max) pen_max = pen
      if (force > force_max) force_max = force
   end subroutine observer_contact_peaks

   !> The maxima of a contact's phase if open (ph_pen, ph_f) at a sample: as
   !> observer_contact_peaks (after observer_phase_change where the contact opens or closes).
   elemental subroutine observer_phase_peaks(open, pen, force, ph_pen, ph_f)
      logical, intent(in) :: open
      real(dp), intent(in) :: pen, force
      real(dp), intent(inout) :: ph_pen, ph_f
      if (open) then
         ph_pen = max(ph_pen, pen); ph_f = max(ph_f, force)
      end if
   end subroutine observer_phase_peaks

   !> Whether the run tracks what (a TRACK_* bit).
   pure logical function tracks(r, what)
      class(results_t), intent(in) :: r
      integer, intent(in) :: what
      tracks = iand(r%tracking, what) == what
   end function tracks

   !> A peak of kind (PEAK_*) of item j (node, contact or link) located by the method inside
   !> an accepted step, with value q (signed: |q| enters the node and link peaks; δ and the
   !> contact force their maxima and those of the open phase), into what the run tracks.
   subroutine observer_peak(o, kind, j, q)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: kind, j
      real(dp), intent(in) :: q
      select case (kind)
      case (PEAK_V)
         if (tracks(o, TRACK_NODE_PEAKS)) o%v_absmax(j) = max(o%v_absmax(j), abs(q))
      case (PEAK_A)
         if (tracks(o, TRACK_NODE_PEAKS)) o%a_absmax(j) = max(o%a_absmax(j), abs(q))
      case (PEAK_PEN)
         if (tracks(o, TRACK_CONTACT_PEAKS)) o%pen_max(j) = max(o%pen_max(j), q)
         if (tracks(o, TRACK_PHASES) .and. o%ph_open(j)) o%ph_pen(j) = max(o%ph_pen(j), q)
      case (PEAK_FORCE)
         if (tracks(o, TRACK_CONTACT_PEAKS)) o%force_max(j) = max(o%force_max(j), q)
         if (tracks(o, TRACK_PHASES) .and. o%ph_open(j)) o%ph_f(j) = max(o%ph_f(j), q)
      case (PEAK_LINK_FORCE)
         if (tracks(o, TRACK_LINK_PEAKS)) call raise_to(o%link_force_absmax(j), abs(q))
      case (PEAK_LINK_DU)
         if (tracks(o, TRACK_LINK_PEAKS)) call raise_to(o%link_du_absmax(j), abs(q))
      end select
   end subroutine observer_peak

   !> The value a located peak of kind, j must exceed to change what is reported: the open
   !> phase's maximum for δ and the contact force (the run's otherwise), the run's peak for
   !> the others (|·|; 0 for a link not yet tracked); huge where the run tracks none of it.
   real(dp) function observer_peak_value(o, kind, j) result(q)
      type(observer_t), intent(in) :: o
      integer, intent(in) :: kind, j
      q = huge(1.0_dp)
      select case (kind)
      case (PEAK_V)
         if (tracks(o, TRACK_NODE_PEAKS)) q = o%v_absmax(j)
      case (PEAK_A)
         if (tracks(o, TRACK_NODE_PEAKS)) q = o%a_absmax(j)
      case (PEAK_PEN)
         if (tracks(o, TRACK_CONTACT_PEAKS)) q = o%pen_max(j)
         if (tracks(o, TRACK_PHASES) .and. o%ph_open(j)) q = o%ph_pen(j)
      case (PEAK_FORCE)
         if (tracks(o, TRACK_CONTACT_PEAKS)) q = o%force_max(j)
         if (tracks(o, TRACK_PHASES) .and. o%ph_open(j)) q = o%ph_f(j)
      case (PEAK_LINK_FORCE)
         if (tracks(o, TRACK_LINK_PEAKS)) q = nan_as_zero(o%link_force_absmax(j))
      case (PEAK_LINK_DU)
         if (tracks(o, TRACK_LINK_PEAKS)) q = nan_as_zero(o%link_du_absmax(j))
      end select
   contains
      pure real(dp) function nan_as_zero(x)
         real(dp), intent(in) :: x
         nan_as_zero = 0.0_dp
         if (.not. ieee_is_nan(x)) nan_as_zero = x
      end function nan_as_zero
   end function observer_peak_value

   !> The number of items of a peak kind (0 for an unknown kind), tracked or not.
   pure integer function peak_items(o, kind) result(n)
      type(observer_t), intent(in) :: o
      integer, intent(in) :: kind
      select case (kind)
      case (PEAK_V, PEAK_A)
         n = o%n_nodes
      case (PEAK_PEN, PEAK_FORCE)
         n = o%n_contacts
      case (PEAK_LINK_FORCE, PEAK_LINK_DU)
         n = o%n_links
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
      if (.not. tracks(o, TRACK_NODE_PEAKS)) return
      o%u_max(i) = max(o%u_max(i), u); o%u_min(i) = min(o%u_min(i), u)
      call raise_absmax(o%u_absmax(i), o%t_absmax(i), t, u)
      if (maximum .and. u > o%u_peak(i)) then
         o%u_peak(i) = u; o%t_peak(i) = t
      end if
   end subroutine observer_extremum

   !> uabs, tabs ← |u|, t where |u| is larger (a node's u_absmax, t_absmax)
   elemental subroutine raise_absmax(uabs, tabs, t, u)
      real(dp), intent(inout) :: uabs, tabs
      real(dp), intent(in) :: t, u
      if (abs(u) > uabs) then
         uabs = abs(u); tabs = t
      end if
   end subroutine raise_absmax

   !> The extremum of u inside a fixed step [t0, t0 + h], located on the cubic Hermite
   !> interpolant of (u, v) at both ends, p(s) = u0 H00 + h v0 H10 + u1 H01 + h v1 H11
   !> (s = τ/h): the root of p'(s), a quadratic, where v changes sign inside the step; into
   !> umax, umin, uabs (tabs) and, a maximum, upk (tpk).
   !> Interpolation error O(h⁴) in u (O(h³) in the time of the extremum), below the
   !> O(h²) of the structural steps themselves (docs/results.md). A turn the step's
   !> accelerations do not support (v reversed by an impulse: no a of the turn's sign at
   !> either end) is not a smooth extremum and is left to the step values.
   pure subroutine hermite_extremum(t0, h, u0, v0, a0, u1, v1, a1, umax, umin, uabs, tabs, upk, &
                                    tpk)
      real(dp), intent(in) :: t0, h, u0, v0, a0, u1, v1, a1
      real(dp), intent(inout) :: umax, umin, uabs, tabs, upk, tpk
      real(dp) :: s(2), p(2)
      integer :: k
      if (.not. (v0*v1 < 0.0_dp)) return
      if (v0 > 0.0_dp .and. min(a0, a1) >= 0.0_dp) return
      if (v0 < 0.0_dp .and. max(a0, a1) <= 0.0_dp) return
      call cubic_hermite_extrema(h, u0, v0, u1, v1, s, p)
      do k = 1, 2
         if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
         call raise_absmax(uabs, tabs, t0 + s(k)*h, p(k))
         umax = max(umax, p(k)); umin = min(umin, p(k))
         if (v0 > 0.0_dp .and. p(k) > upk) then      ! a local maximum
            upk = p(k); tpk = t0 + s(k)*h
         end if
      end do
   end subroutine hermite_extremum

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
