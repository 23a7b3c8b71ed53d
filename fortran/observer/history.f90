!> The observer's history (docs/run-layer.md "The observer"): the sizes of a run's results,
!> the sample of an accepted state and the recording cadence of its rows, and the event
!> table of the contact phases with its bound on a long pounding chain's memory.
submodule (martello_observer) history
   use martello_integrator_settings, only: integrator_name
   use martello_registry, only: INTEGRATORS, TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, &
      TRACK_CONTACT_PEAKS, TRACK_PHASES
   use martello_run_quantities, only: NEVENT, EV_T_ON, EV_T_OFF, EV_V_IN, EV_V_OUT, EV_MAX_PEN, &
      EV_MAX_FORCE, C_CHATTER
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
   implicit none

   !> History rows allocated at the start; it grows by doubling beyond (record).
   integer, parameter :: HIST_START = 4096

contains

   !> Size the results of a run (every integrator) and take the settings the measurement
   !> needs: the output grid t = k·dt, k ≤ n_grid (whole intervals until t_end is reached:
   !> the last one is reported as t_reached, never a shortened one labelled t_end), the
   !> recording cadence and the divergence rule.
   !> The budget: a run whose output grid alone needs more than max_steps steps is refused
   !> before it starts (every integrator takes at least one step per grid point);
   !> stat = MARTELLO_ERR_LIMIT, or MARTELLO_ERR_MEMORY if the arrays cannot be allocated.
   module procedure observer_init
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
      o%clock_last = o%clock0; o%clock_watched = o%clock0
      o%watch_stride = 1; o%watch_count = 0
      steps = 1.0_dp
      if (s%dt > 0.0_dp .and. s%t_end > 0.0_dp) steps = max(1.0_dp, s%t_end/s%dt*(1.0_dp - 1.0e-12_dp))
      if (steps > o%max_steps .or. .not. ieee_is_finite(steps)) then
         write (o%message, '(a,a,a,a,a,a)') integrator_name(o%kind), ': the run needs at least ', &
            sci(steps, 3), ' steps (t_end/dt), more than max_steps = ', sci(o%max_steps, 3), &
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
   end procedure observer_init

   !> Which contacts keep every phase (docs/results.md): all of them while the scene has at
   !> most max_contacts contacts (max_contacts < 0: always); past it, the history's output
   !> contacts, and the others their first and last phase alone (keep_event). After
   !> observer_init.
   module procedure observer_phase_lists
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
   end procedure observer_phase_lists

   !> An accepted state at t (once per accepted step and at t = 0, after the step's phase
   !> changes): phase maxima and peaks; the energy terms where recorded and on the energy
   !> grid (energy_grid), the largest |balance| and the divergence test on the grid alone;
   !> a history row where recorded. k: the grid point t = k·dt of the state, or −1. u, v, a on nodes 0:n;
   !> u_prev … the previous state if the method keeps it (saves a copy). stat:
   !> MARTELLO_ERR_DIVERGED, with the message, when the run must stop.
   !> folded: the state has been measured item by item already (observer_block, which hands
   !> pen, force, link_f and link_du for the history row alone, where recorded).
   !> energies = [kinetic, links, contacts] at this state, from a method that keeps its own
   !> element states (no ms), where observer_energy_due.
   !> row: the state is an output row on the method's interpolant inside a step, not a step:
   !> measured and recorded, but not a sample of the energy grid (the largest |balance|, the
   !> divergence test), nor a step of the budget, so that neither depends on the output
   !> (docs/run-layer.md, "the energy terms").
   module procedure observer_sample_i8
      real(dp) :: e_mech
      logical :: due, grid, measured, is_row
      stat = MARTELLO_OK
      is_row = .false.
      if (present(row)) is_row = row
      grid = energy_grid(o, k) .and. .not. is_row
      due = grid .or. recorded(o, k) .or. (traced(o, k) .and. .not. is_row)
      if (.not. is_row) o%nsamples = o%nsamples + 1
      measured = .false.
      if (present(folded)) measured = folded
      if (.not. measured) then
         if (tracks(o, TRACK_PHASES)) &
            call phase_peaks(o%ph_open(1:size(pen)), pen, force, o%ph_pen(1:size(pen)), &
                             o%ph_f(1:size(pen)))
         if (tracks(o, TRACK_CONTACT_PEAKS)) &
            call contact_peaks(pen, force, o%pen_max(1:size(pen)), o%force_max(1:size(pen)))
         call track(o, m, t, u(1:), v(1:), a(1:), link_f, link_du, u_prev, v_prev, a_prev)
      end if
      if (o%fq%n > 0) call functionals_track(o%fq, t, u(1:), v(1:), a(1:), o%fixed_steps)
      ! the next step's start
      if (o%smooth_steps .and. .not. is_row) o%chatter_prev = o%counters(C_CHATTER)
      if (.not. is_row) o%prev_t = t
      if (due) call energy_at(o, m, ms, u, v, a, grid, energies, e_mech)
      if (traced(o, k) .and. .not. is_row) then
         ! the traced contact's force: from the method that measured itself, or handed
         if (measured) then
            call trace_append(o, t, o%trace_f, u, stat)
         else
            call trace_append(o, t, force(o%trace_contact), u, stat)
         end if
         if (stat /= MARTELLO_OK) then
            call observer_finish(o, t); return
         end if
      end if
      if (recorded(o, k)) then
         call record(o, t, u(1:), v(1:), a(1:), pen, force, link_f, link_du, stat)
         if (stat /= MARTELLO_OK) then
            call observer_finish(o, t); return
         end if
      end if
      if (grid) call check_divergence(o, t, e_mech, u, v, stat)
      if (stat == MARTELLO_OK .and. .not. is_row) call observer_watch(o, t, stat)
   end procedure observer_sample_i8

   !> observer_sample with the grid point k as a default integer (the C door, k ≤ 2^31).
   module procedure observer_sample_i4
      call observer_sample_i8(o, m, ms, t, u, v, a, pen, force, int(k, i8), stat, link_f, &
                              link_du, u_prev, v_prev, a_prev, folded, energies, row)
   end procedure observer_sample_i4

   !> The recording cadence: t = 0, every every-th output grid point, and the last one.
   module procedure recorded
      recorded = k == 0
      if (k > 0) recorded = mod(k, int(o%every, i8)) == 0 .or. k >= o%n_grid
   end procedure recorded

   !> Whether the sample at grid point k (−1: off the grid) enters the step trace: every
   !> grid point, where a contact is traced (martello_run_set_trace).
   module procedure traced
      traced = o%trace_contact > 0 .and. k >= 0
   end procedure traced

   !> Append one history row (grows by doubling when a variable-step integrator needs it).
   !> link_f, link_du absent: NaN columns. stat = MARTELLO_ERR_MEMORY (message set) if the
   !> history cannot grow.
   module procedure record
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
   end procedure record

   !> A phase of contact c ends: an event row, or for a contact that keeps its first and
   !> last phase alone (observer_phase_lists), its first phase, then its last one, in place.
   module procedure keep_event
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
   end procedure keep_event

   !> The contact phases a finished run lists (martello_run_events): the rows of the event
   !> table, then the first and last phase of each contact that keeps them alone
   !> (observer_phase_lists). n: their number; contact (0-based) and values filled when
   !> present.
   module procedure observer_events
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
   end procedure observer_events

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
end submodule history
