!> The observer of a dynamic run (docs/run-layer.md): the history and its recording
!> cadence, contact phases, peaks, the energy balance, divergence detection, the counters
!> and the final message, for every integrator. The methods (martello_fixed_step's steppers,
!> the C integrators through c/martello_internal.h) hand it accepted states, work
!> increments and the phase changes they locate; a method that measures itself (the fused
!> chain step) hands its states a block at a time (observer_block). results_t is what a
!> finished run exposes (martello_api_results); observer_t adds the working state of the
!> measurement.
!>
!> This module is the observer's face: its types and the interfaces of its procedures. The
!> procedures are in its submodules, one concept each (fortran/observer/):
!>   history — the run's sizes, the sample and its recording cadence, the event table;
!>   phases  — contact phases and their location on the free side of a step;
!>   peaks   — located peaks of nodes, contacts and links, inside the steps;
!>   block   — the bulk entry of a method that measures itself;
!>   energy  — the start of the run, works and energy terms, divergence;
!>   budget  — max_steps, max_wall, the progress callback, failure and finish;
!>   functionals — linear functionals R·u of the state (a frame's or building's forces);
!>   trace   — one contact's force and the energies at every step, whatever is recorded.
module martello_observer
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_element_rows, only: rows_t
   use martello_assembly, only: mech_state_t
   use martello_links, only: NPAR_LINK
   use martello_integrator_settings, only: integrator_settings_t
   use martello_run_quantities, only: NCOUNTERS, NENERGY
   use martello_registry, only: TRACK_ALL
   use, intrinsic :: iso_c_binding, only: c_funptr, c_ptr, c_null_funptr, c_null_ptr, c_int, &
      c_double, c_long_long
   implicit none
   private
   public :: results_t, observer_t, node_block_t, functionals_t, progress_callback, tracks
   ! linear functionals of the state (functionals)
   public :: functionals_start, functionals_track
   ! a run's sizes and what it lists (history)
   public :: observer_init, observer_phase_lists, observer_sample, observer_block, &
      observer_energy_due, observer_events
   ! what a method hands over (energy, phases, peaks)
   public :: observer_begin, observer_work, observer_open_phase, observer_close_phase, &
      observer_add_impact, observer_penalty_phases, free_side_crossing, observer_extremum, &
      observer_peak, observer_peak_value, peak_items
   ! the end of a run (budget)
   public :: observer_fail, observer_failed, observer_fail_nonfinite, observer_finish, &
      observer_close, observer_watch

   !> Linear functionals q = R·u of the state, tracked at every accepted sample whatever
   !> the history records (docs/results.md, "Frames and buildings": a frame's or building's
   !> member end forces, drifts, storey forces, plan points). R in compressed rows: row f has
   !> val(ptr(f):ptr(f+1)-1) on the nodes col(…) (1..n). Their signed extremes and times, over
   !> the samples and inside each stretch between two samples where the rate R·v changes
   !> sign (on the cubic Hermite of (q, R·v)); per pair of rows (pair(:, p)) the largest
   !> resultant √(q_a² + q_b²) over the samples and inside the stretches where its square
   !> turns, and its time. q0, r0, a0: each row at the last sample; q1, r1, a1 at the one
   !> being taken. t0 < 0: no sample yet.
   type :: functionals_t
      integer :: n = 0
      integer, allocatable :: ptr(:), col(:), pair(:, :)
      real(dp), allocatable :: val(:)
      real(dp), allocatable :: q_max(:), q_min(:), t_max(:), t_min(:), res_max(:), t_res(:)
      real(dp), allocatable :: q0(:), r0(:), a0(:), q1(:), r1(:), a1(:)
      real(dp) :: t0 = -1.0_dp
   end type functionals_t

   type :: results_t
      !> what the run tracks (TRACK_* bits, martello_run_set_tracking): the arrays of what it
      !> does not track have no entries (the accessors give NaN), its phases no rows;
      !> impacts are always counted
      integer :: tracking = TRACK_ALL
      integer :: n_nodes = 0, n_contacts = 0, n_links = 0
      !> the linear functionals tracked (martello_run_set_functionals)
      type(functionals_t) :: fq
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
      ! are located on each step's polynomial (the peaks submodule)
      real(dp), allocatable :: u_max(:), u_min(:), v_absmax(:), a_absmax(:)
      !> the largest local maximum of u (u_peak at t_peak)
      real(dp), allocatable :: u_peak(:), t_peak(:)
      !> the largest |u| and its time
      real(dp), allocatable :: u_absmax(:), t_absmax(:)
      !> a fixed-step method: the extrema of u and v are located on each step's cubic Hermite
      logical :: fixed_steps = .false.
      real(dp), allocatable :: pen_max(:), force_max(:)
      !> per link: max |force| and max |elongation| (storey shear and drift of a frame)
      real(dp), allocatable :: link_force_absmax(:), link_du_absmax(:)
      integer, allocatable :: impacts(:)
      !> the step trace (trace; martello_run_set_trace): contact trace_contact's force, the
      !> kinetic and recoverable energies and u of the nodes trace_nodes at every grid point
      !> of the run (t = k·dt), whatever the history records: trace(:, j) = [t, force,
      !> kinetic, recoverable, u(trace_nodes)], j ≤ ntrace; trace_f: that force at the
      !> sample, from a method that measures itself
      integer :: trace_contact = 0, ntrace = 0
      integer, allocatable :: trace_nodes(:)
      real(dp), allocatable :: trace(:, :)
      real(dp) :: trace_f = 0.0_dp
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
      ! energy: evaluated every energy_interval-th sample (energy_grid) and where recorded
      integer :: energy_interval = 1
      integer(i8) :: nsamples = -1              !< accepted steps so far (t = 0 is sample 0)
      ! the budget (max_steps, max_wall [s], 0: none) and the caller's progress callback,
      ! watched every watch_stride samples (observer_watch: 1 to WATCH_EVERY, by the pace)
      real(dp) :: t_end = 0.0_dp, max_steps = huge(1.0_dp), max_wall = 0.0_dp
      integer(i8) :: clock0 = 0, clock_last = 0, clock_rate = 1
      integer(i8) :: clock_watched = 0, watch_stride = 1, watch_count = 0
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
      !> forces a located peak of |a| must not straddle). con_rows: each contact's nodes,
      !> for the phase changes the method does not name them at (observer_block does)
      real(dp), allocatable :: node_change(:)
      type(rows_t) :: con_rows                 !< the contacts' rows: their nodes
      logical :: has_con_rows = .false.
      integer(i8) :: chatter_prev = 0_i8
      !> per contact, for the general fixed-step path: its force and force rate at the
      !> previous sample (observer_block computes them again from the previous state)
      real(dp), allocatable :: c_prev_f(:), c_prev_fr(:)
      !> the peak of |a| on fixed steps (observer_a_parabolas): a sample k that raised it
      !> waits two samples for the parabola through k − 1, k, k + 1 and the tests of its
      !> span with k − 2 and k + 2. Per node: a at k − 2, k − 1, k, k + 1 and the sample k of
      !> its latest candidate modulo 256 (a_gen; the lists name the candidates of the last
      !> three samples at most, so no two stamps in use are equal); the candidates of the
      !> last two samples (pend1: k = the last, pend2: the one before), with the time and the
      !> chatter count of their sample k − 1; a_back: every node's a at the sample before
      !> the last (a candidate's k − 2)
      real(dp), allocatable :: a_m2(:), a_m1(:), a_0(:), a_p1(:), a_back(:)
      integer(int8), allocatable :: a_gen(:)
      integer, allocatable :: pend1(:), pend2(:)
      integer :: npend1 = 0, npend2 = 0
      real(dp) :: pend1_t0 = 0.0_dp, pend2_t0 = 0.0_dp
      integer(i8) :: pend1_stamp = 0_i8, pend2_stamp = 0_i8
      !> a method that measures itself (observer_block): the link maxima per node and pair,
      !> from which every linear link's peaks follow (observer_close): the largest |u_i| and
      !> |v_i| (the links to ground), |u_i − u_{i+1}| and |v_i − v_{i+1}| (the links of the
      !> pair), over the samples and the extrema located inside the steps; only the kinds
      !> the scene has (no entries otherwise)
      real(dp), allocatable :: gu(:), gv(:), pu(:), pv(:)
   end type observer_t

   !> What a method that measures itself holds of its scene beyond its nodes, for
   !> observer_block (the fused chain step makes it once and keeps its laws in it):
   !> * the pair contacts, between nodes p and p + 1 (1 ≤ p < n): contact first + p
   !>   (first ≥ 0), else number(p) (0: none); δ = s(u_p − u_{p+1}) − gap; on the branch that
   !>   pushes the force is k δ + c δ̇, a Kelvin law clipped at 0 where law(p) says so
   !>   (AFFINE_* of martello_contact_laws; c = 0 for the linear law). Each parameter array
   !>   runs from 0 and is read at p·stride: stride 0 holds one value for every pair;
   !> * the other contacts one by one (their indices among the model's contacts added one by
   !>   one, xg, and among all its contacts, xc) and the bilinear links (bl among those
   !>   added one by one, blo among all), whose laws are the model's.
   type :: node_block_t
      logical :: pairs = .false., kelvin = .false.
      integer :: first = -1
      integer, allocatable :: number(:)
      real(dp), allocatable :: sgn(:), gap(:), k(:), c(:)
      integer(int8), allocatable :: law(:)
      integer :: ss = 0, sg = 0, sk = 0, sc = 0, sl = 0
      integer, allocatable :: xg(:), xc(:), bl(:), blo(:)
   end type node_block_t

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

   !> ph_kept of a contact whose phases are all rows
   integer, parameter :: LISTED = -huge(1)
   !> The fix of the out-of-memory line for the history and the phase list of a run.
   character(len=*), parameter :: FIX_RECORD_LESS = &
      'record less (output.every, output.nodes, output.contacts)', &
      FIX_FEWER_PHASES = 'track fewer contact phases (analysis.output.track) or use a smaller scene'

   !> Samples of one observer_sample call: the grid point k as a default or a 64-bit integer.
   interface observer_sample
      module procedure observer_sample_i8, observer_sample_i4
   end interface observer_sample

   interface
      ! ---- history --------------------------------------------------------------------
      !> Size the results of a run (every integrator) and take the settings the measurement
      !> needs (history.f90).
      module subroutine observer_init(o, s, n_nodes, n_contacts, out_nodes, out_contacts, &
                                      capacity, n_links, out_links, stat, tracking)
         type(observer_t), intent(inout) :: o
         type(integrator_settings_t), intent(in) :: s
         integer, intent(in) :: n_nodes, n_contacts, out_nodes(:), out_contacts(:), capacity, &
                                n_links, out_links(:)
         integer, intent(out) :: stat
         integer, intent(in), optional :: tracking
      end subroutine observer_init
      module subroutine observer_phase_lists(o, max_contacts, stat)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: max_contacts
         integer, intent(out) :: stat
      end subroutine observer_phase_lists
      module subroutine observer_sample_i8(o, m, ms, t, u, v, a, pen, force, k, stat, link_f, &
                                           link_du, u_prev, v_prev, a_prev, folded, energies, row)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
         integer(i8), intent(in) :: k
         integer, intent(out) :: stat
         real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
         logical, intent(in), optional :: folded
         real(dp), intent(in), optional :: energies(3)
         logical, intent(in), optional :: row
      end subroutine observer_sample_i8
      module subroutine observer_sample_i4(o, m, ms, t, u, v, a, pen, force, k, stat, link_f, &
                                           link_du, u_prev, v_prev, a_prev, folded, energies, row)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         real(dp), intent(in) :: t, u(0:), v(0:), a(0:), pen(:), force(:)
         integer, intent(in) :: k
         integer, intent(out) :: stat
         real(dp), intent(in), optional :: link_f(:), link_du(:), u_prev(:), v_prev(:), a_prev(:)
         logical, intent(in), optional :: folded
         real(dp), intent(in), optional :: energies(3)
         logical, intent(in), optional :: row
      end subroutine observer_sample_i4
      pure module logical function recorded(o, k)
         type(observer_t), intent(in) :: o
         integer(i8), intent(in) :: k
      end function recorded
      pure module logical function traced(o, k)
         type(observer_t), intent(in) :: o
         integer(i8), intent(in) :: k
      end function traced
      module subroutine record(r, t, u, v, a, pen, force, link_f, link_du, stat)
         class(results_t), intent(inout) :: r
         real(dp), intent(in) :: t, u(:), v(:), a(:), pen(:), force(:)
         real(dp), intent(in), optional :: link_f(:), link_du(:)
         integer, intent(out) :: stat
      end subroutine record
      module subroutine keep_event(o, c, values)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         real(dp), intent(in) :: values(:)
      end subroutine keep_event
      module subroutine observer_events(o, n, contact, values)
         type(observer_t), intent(in) :: o
         integer, intent(out) :: n
         integer, intent(out), optional :: contact(:)
         real(dp), intent(out), optional :: values(:, :)
      end subroutine observer_events

      ! ---- phases ---------------------------------------------------------------------
      module subroutine observer_open_phase(o, c, t_on, v_in)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         real(dp), intent(in) :: t_on, v_in
      end subroutine observer_open_phase
      module subroutine observer_close_phase(o, c, t_off, v_out, pen, force)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         real(dp), intent(in) :: t_off, v_out
         real(dp), intent(in), optional :: pen, force
      end subroutine observer_close_phase
      module subroutine observer_add_impact(o, c, t, v_in, v_out, pen, force)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         real(dp), intent(in) :: t, v_in, v_out, pen, force
      end subroutine observer_add_impact
      module subroutine observer_penalty_phases(o, m, ms, un, vn, an, u, v, a, t, h)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         real(dp), intent(in) :: un(0:), vn(0:), an(0:), u(0:), v(0:), a(0:), t, h
      end subroutine observer_penalty_phases
      module subroutine contact_force_rate(m, ms, c, r, q, f, fr)
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         integer, intent(in) :: c
         real(dp), intent(in) :: r, q
         real(dp), intent(out) :: f, fr
      end subroutine contact_force_rate
      module subroutine contact_step_peaks(o, c, h, d0, r0, f0, fr0, d1, r1, f1, fr1)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         real(dp), intent(in) :: h, d0, r0, f0, fr0, d1, r1, f1, fr1
      end subroutine contact_step_peaks
      module subroutine phase_change(o, c, on, pen, force, d0, r0, q0, d1, r1, q1, t, h, nodes)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: c
         logical, intent(in) :: on
         real(dp), intent(in) :: pen, force, d0, r0, q0, d1, r1, q1, t, h
         integer, intent(in), optional :: nodes(2)
      end subroutine phase_change
      pure module real(dp) function free_side_crossing(d, rate, acc, lo, hi) result(tau)
         real(dp), intent(in) :: d, rate, acc, lo, hi
      end function free_side_crossing

      ! ---- peaks ----------------------------------------------------------------------
      module subroutine track(o, m, t, u, v, a, link_f, link_du, u_prev, v_prev, a_prev)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         real(dp), intent(in) :: t, u(:), v(:), a(:)
         real(dp), intent(in), optional :: link_f(:), link_du(:)
         real(dp), intent(in), optional :: u_prev(:), v_prev(:), a_prev(:)
      end subroutine track
      module subroutine observer_a_parabolas(o, m, t, a, sample)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         real(dp), intent(in) :: t, a(:)
         integer(i8), intent(in) :: sample
      end subroutine observer_a_parabolas
      pure module integer(int8) function stamp(sample)
         integer(i8), intent(in) :: sample
      end function stamp
      elemental module subroutine node_samples(t, u, v, a, umax, umin, vmax, amax, uabs, tabs, &
                                               raised)
         real(dp), intent(in) :: t, u, v, a
         real(dp), intent(inout) :: umax, umin, vmax, amax, uabs, tabs
         logical, intent(out) :: raised
      end subroutine node_samples
      elemental module logical function node_turns(vn, an, v, a) result(turns)
         real(dp), intent(in) :: vn, an, v, a
      end function node_turns
      elemental module subroutine node_step_extrema(t, t_prev, un, vn, an, u, v, a, umax, umin, &
                                                    vmax, uabs, tabs, upk, tpk)
         real(dp), intent(in) :: t, t_prev, un, vn, an, u, v, a
         real(dp), intent(inout) :: umax, umin, vmax, uabs, tabs, upk, tpk
      end subroutine node_step_extrema
      elemental module subroutine contact_peaks(pen, force, pen_max, force_max)
         real(dp), intent(in) :: pen, force
         real(dp), intent(inout) :: pen_max, force_max
      end subroutine contact_peaks
      elemental module subroutine phase_peaks(open, pen, force, ph_pen, ph_f)
         logical, intent(in) :: open
         real(dp), intent(in) :: pen, force
         real(dp), intent(inout) :: ph_pen, ph_f
      end subroutine phase_peaks
      pure module logical function tracks(r, what)
         class(results_t), intent(in) :: r
         integer, intent(in) :: what
      end function tracks
      module subroutine observer_peak(o, kind, j, q)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: kind, j
         real(dp), intent(in) :: q
      end subroutine observer_peak
      module real(dp) function observer_peak_value(o, kind, j) result(q)
         type(observer_t), intent(in) :: o
         integer, intent(in) :: kind, j
      end function observer_peak_value
      pure module integer function peak_items(o, kind) result(n)
         type(observer_t), intent(in) :: o
         integer, intent(in) :: kind
      end function peak_items
      module subroutine observer_extremum(o, i, t, u, maximum)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: i
         real(dp), intent(in) :: t, u
         logical, intent(in) :: maximum
      end subroutine observer_extremum
      elemental module subroutine raise_to(x, y)
         real(dp), intent(inout) :: x
         real(dp), intent(in) :: y
      end subroutine raise_to
      pure module subroutine link_step_extremum(kind, par, h, du0, dv0, da0, du1, dv1, da1, f1, &
                                                fmax, dmax)
         integer, intent(in) :: kind
         real(dp), intent(in) :: par(NPAR_LINK), h, du0, dv0, da0, du1, dv1, da1, f1
         real(dp), intent(inout) :: fmax, dmax
      end subroutine link_step_extremum
      pure module subroutine step_maxima(h, d0, r0, f0, fr0, d1, r1, f1, fr1, dm, fm)
         real(dp), intent(in) :: h, d0, r0, f0, fr0, d1, r1, f1, fr1
         real(dp), intent(out) :: dm, fm
      end subroutine step_maxima
      pure module subroutine cubic_hermite_extrema(h, u0, v0, u1, v1, s, p)
         real(dp), intent(in) :: h, u0, v0, u1, v1
         real(dp), intent(out) :: s(2), p(2)
      end subroutine cubic_hermite_extrema
      elemental module real(dp) function step_absmax(h, q0, r0, q1, r1) result(x)
         real(dp), intent(in) :: h, q0, r0, q1, r1
      end function step_absmax

      ! ---- block ----------------------------------------------------------------------
      !> The state at t = t_k of a method that measures itself, a block of nodes and their
      !> pair contacts at a time (block.f90).
      module subroutine observer_block(o, m, t, h, k, blk, un, vn, an, u, v, a, br, xbr, bf, &
                                       bdu, stat, energies)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         real(dp), intent(in) :: t, h
         integer(i8), intent(in) :: k
         type(node_block_t), intent(in) :: blk
         real(dp), intent(in) :: un(0:), vn(0:), an(0:), u(0:), v(0:), a(0:)
         integer(int8), intent(in) :: br(0:), xbr(:)
         real(dp), intent(in) :: bf(:), bdu(:)
         integer, intent(out) :: stat
         real(dp), intent(in), optional :: energies(3)
      end subroutine observer_block
      module subroutine block_maxima(o, m, st)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         integer, intent(out) :: st
      end subroutine block_maxima
      module subroutine observer_close(o, m)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
      end subroutine observer_close

      ! ---- energy ---------------------------------------------------------------------
      module subroutine observer_begin(o, m, ms, u, v, a, energy_interval, advice, ke_aMa, &
                                       stat, energies)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         real(dp), intent(in) :: u(0:), v(0:), a(0:)
         integer, intent(in) :: energy_interval
         character(len=*), intent(in) :: advice
         real(dp), intent(in) :: ke_aMa
         integer, intent(out) :: stat
         real(dp), intent(in), optional :: energies(3)
      end subroutine observer_begin
      module subroutine observer_work(o, external, damping, links, contact, impact, internal)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in), optional :: external, damping, links, contact, impact, internal
      end subroutine observer_work
      !> Append the grid point at t (force f of the traced contact, the energies of the
      !> sample, u of the traced nodes) to the step trace; stat = MARTELLO_ERR_MEMORY
      !> (message set) if it cannot grow.
      module subroutine trace_append(o, t, f, u, stat)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t, f, u(0:)
         integer, intent(out) :: stat
      end subroutine trace_append
      module logical function observer_energy_due(o, k) result(due)
         type(observer_t), intent(in) :: o
         integer(i8), intent(in) :: k
      end function observer_energy_due
      module logical function energy_grid(o, k) result(grid)
         type(observer_t), intent(in) :: o
         integer(i8), intent(in) :: k
      end function energy_grid
      module subroutine energy_at(o, m, ms, u, v, a, grid, energies, e_mech)
         type(observer_t), intent(inout) :: o
         type(model_t), intent(in) :: m
         type(mech_state_t), intent(in) :: ms
         real(dp), intent(in) :: u(0:), v(0:), a(0:)
         logical, intent(in) :: grid
         real(dp), intent(in), optional :: energies(3)
         real(dp), intent(out) :: e_mech
      end subroutine energy_at
      module subroutine check_divergence(o, t, e_mech, u, v, stat)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t, e_mech, u(0:), v(0:)
         integer, intent(out) :: stat
      end subroutine check_divergence

      ! ---- budget ---------------------------------------------------------------------
      module subroutine observer_watch(o, t, stat)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t
         integer, intent(inout) :: stat
      end subroutine observer_watch
      module subroutine observer_fail(o, code, t_reached, message, stat)
         type(observer_t), intent(inout) :: o
         integer, intent(in) :: code
         real(dp), intent(in) :: t_reached
         character(len=*), intent(in) :: message
         integer, intent(out) :: stat
      end subroutine observer_fail
      module subroutine observer_failed(o, t, code)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t
         integer, intent(inout) :: code
      end subroutine observer_failed
      module subroutine observer_fail_nonfinite(o, t, stat)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t
         integer, intent(out) :: stat
      end subroutine observer_fail_nonfinite
      module subroutine observer_finish(o, t_reached)
         type(observer_t), intent(inout) :: o
         real(dp), intent(in) :: t_reached
      end subroutine observer_finish

      ! ---- functionals ----------------------------------------------------------------
      !> Size the results of the functionals f holds (functionals.f90); stat /= 0: no memory.
      module subroutine functionals_start(f, stat)
         type(functionals_t), intent(inout) :: f
         integer, intent(out) :: stat
      end subroutine functionals_start
      !> The functionals at the accepted state (u, v, a on nodes 1..n) at t of a fixed-step
      !> method or not.
      module subroutine functionals_track(f, t, u, v, a, fixed_steps)
         type(functionals_t), intent(inout) :: f
         real(dp), intent(in) :: t, u(:), v(:), a(:)
         logical, intent(in) :: fixed_steps
      end subroutine functionals_track
   end interface
end module martello_observer
