!> The observer's contact phases (docs/run-layer.md "The observer"): one event per phase
!> with onset and separation times and speeds and the phase's largest penetration and force;
!> for the penalty contacts of a fixed step, the onset and separation located on the free
!> side of the step (free_side_crossing) and the maxima inside it.
submodule (martello_observer) phases
   use martello_registry, only: TRACK_CONTACT_PEAKS, TRACK_PHASES
   use martello_element_rows, only: row_dot, row_lo, row_hi
   use martello_run_quantities, only: C_EVENTS
   use martello_contact_laws, only: contact_force, LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING
   implicit none

contains

   !> Contact c starts a phase at t_on, approaching at v_in (δ̇ > 0).
   module procedure observer_open_phase
      o%ph_open(c) = .true.
      o%impacts(c) = o%impacts(c) + 1
      call node_change_at(o, c, t_on)
      if (.not. tracks(o, TRACK_PHASES)) return
      o%ph_t(c) = t_on; o%ph_v(c) = v_in; o%ph_pen(c) = 0.0_dp; o%ph_f(c) = 0.0_dp
   end procedure observer_open_phase

   !> Contact c ends its phase at t_off, leaving at v_out. pen, force: the contact's state at
   !> the sample that closes it, when the method decides the closing on that state (it then
   !> enters the phase maxima, as the states of the phase's other steps do).
   module procedure observer_close_phase
      o%ph_open(c) = .false.
      call node_change_at(o, c, t_off)
      if (.not. tracks(o, TRACK_PHASES)) return
      if (present(pen)) o%ph_pen(c) = max(o%ph_pen(c), pen)
      if (present(force)) o%ph_f(c) = max(o%ph_f(c), force)
      call keep_event(o, c, [o%ph_t(c), t_off, o%ph_v(c), v_out, o%ph_pen(c), o%ph_f(c)])
   end procedure observer_close_phase

   !> An instantaneous phase of contact c at t (an impact resolved by an impulse): approach
   !> and separation speeds, penetration and force (or impulse) at the impact.
   module procedure observer_add_impact
      if (tracks(o, TRACK_PHASES)) call keep_event(o, c, [t, t, v_in, v_out, pen, force])
      o%impacts(c) = o%impacts(c) + 1
      call node_change_at(o, c, t)
   end procedure observer_add_impact

   !> Contact c changed phase at t: its nodes' forces jump or kink there (node_change, read
   !> by observer_a_parabolas). nodes: the contact's, where the method names them
   !> (observer_block); else every node of its row (con_rows).
   subroutine node_change_at(o, c, t, nodes)
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
   end subroutine node_change_at

   !> Phases of the penalty contacts of a fixed step (t − h, t], from the committed state
   !> ms: a contact that closed starts a phase at the onset located on the free side of the
   !> step by the quadratic δ + δ̇τ + ½δ̈τ² = 0 from the start (O(h³) in time, speed
   !> extrapolated likewise; one event of the method); one that opened ends it at the
   !> separation located likewise back from the end. un … the state at t − h, u … at t.
   !> On a smooth method's step (smooth_steps), a phase spanning the step also has its
   !> maxima located inside it (contact_step_peaks).
   module procedure observer_penalty_phases
      integer :: c
      real(dp) :: f, fr
      logical :: located
      located = allocated(o%c_prev_f) .and. o%prev_t >= 0.0_dp .and. t > o%prev_t
      do c = 1, m%ncontact
         if (.not. ms%is_penalty(c)) cycle
         if (located) then
            call contact_force_rate(m, ms, c, row_dot(m%con, c, v), row_dot(m%con, c, a), f, fr)
            if (o%ph_open(c) .and. ms%con_on(c)) &
               call contact_step_peaks(o, c, t - o%prev_t, row_dot(m%con, c, un) - m%con_gap(c), &
                                       row_dot(m%con, c, vn), o%c_prev_f(c), o%c_prev_fr(c), &
                                       ms%con_pen(c), row_dot(m%con, c, v), f, fr)
            o%c_prev_f(c) = f; o%c_prev_fr(c) = fr
         end if
         if (ms%con_on(c) .neqv. o%ph_open(c)) &
            call phase_change(o, c, ms%con_on(c), ms%con_pen(c), ms%con_f(c), &
                              row_dot(m%con, c, un) - m%con_gap(c), row_dot(m%con, c, vn), &
                              row_dot(m%con, c, an), row_dot(m%con, c, u) - m%con_gap(c), &
                              row_dot(m%con, c, v), row_dot(m%con, c, a), t, h)
         if (tracks(o, TRACK_PHASES)) call phase_peaks(o%ph_open(c), ms%con_pen(c), ms%con_f(c), &
                                                       o%ph_pen(c), o%ph_f(c))
      end do
   end procedure observer_penalty_phases

   !> The force f of penalty contact c of the committed state ms and its rate
   !> Ṗ = P_δ δ̇ + P_δ̇ δ̈ from the law's tangents (the linear and Kelvin laws in line), at
   !> the rates r = δ̇, q = δ̈ (0 where the contact does not push).
   module procedure contact_force_rate
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
   end procedure contact_force_rate

   !> The maxima of penalty contact c located inside a smooth fixed step of h while its
   !> phase spans the step (open at both ends, the phase change of the step not yet handed
   !> over; step_maxima: δ > 0 at both ends, the force where the law pushes at both ends),
   !> into the run's and the phase's maxima, as tracked. The one procedure of the general
   !> path and of observer_block's contacts one by one (its pair contacts take step_maxima
   !> in line).
   module procedure contact_step_peaks
      real(dp) :: dm, fm
      call step_maxima(h, d0, r0, f0, fr0, d1, r1, f1, fr1, dm, fm)
      if (tracks(o, TRACK_CONTACT_PEAKS)) call contact_peaks(dm, fm, o%pen_max(c), o%force_max(c))
      if (tracks(o, TRACK_PHASES)) call phase_peaks(.true., dm, fm, o%ph_pen(c), o%ph_f(c))
   end procedure contact_step_peaks

   !> Penalty contact c opens (on) or closes (not on) in the fixed step (t − h, t], its
   !> phase being closed or open: a phase starts at the onset located on the free side of the
   !> step by the quadratic δ + δ̇τ + ½δ̈τ² = 0 from the start (O(h³) in time, speed
   !> extrapolated likewise; one event of the method), or ends, its maxima taken with the
   !> contact's state at t (pen, force), at the separation located likewise back from the
   !> end. d0, r0, q0 and d1, r1, q1: δ, δ̇, δ̈ at t − h and at t. nodes: the contact's,
   !> where the caller names them (observer_block).
   module procedure phase_change
      real(dp) :: tau
      if (on) then
         tau = free_side_crossing(d0, r0, q0, 0.0_dp, h)
         call observer_open_phase(o, c, t - h + tau, r0 + q0*tau)
         o%counters(C_EVENTS) = o%counters(C_EVENTS) + 1_i8
         if (present(nodes)) call node_change_at(o, c, t - h + tau, nodes)
      else
         tau = free_side_crossing(d1, r1, q1, -h, 0.0_dp)
         call observer_close_phase(o, c, t + tau, r1 + q1*tau, pen, force)
         if (present(nodes)) call node_change_at(o, c, t + tau, nodes)
      end if
   end procedure phase_change

   !> Event location on the free side of a step: the first root of d + rate·τ + ½acc·τ² in
   !> [lo, hi] (O(h³) in time when the free motion is smooth); linear fallback, else hi.
   module procedure free_side_crossing
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
   end procedure free_side_crossing
end submodule phases
