!> The observer's peaks, every one located inside the steps (docs/results.md, docs/run-layer.md
!> "The observer"): where the rate of a quantity changes sign inside a step, its extremum is
!> located on what the method knows of its motion there — on a fixed step the cubic Hermite
!> of (q, q̇) at both ends, for |a| the parabola through three samples; the adaptive methods
!> hand theirs (observer_extremum, observer_peak).
submodule (martello_observer) peaks
   use martello_assembly, only: load_breakpoint
   use martello_element_rows, only: row_dot1
   use martello_links, only: link_force, LINK_SPRING, LINK_BAR, LINK_BILINEAR, LINK_DASHPOT, &
      LINK_FLUID_DAMPER, L_STIFF
   use martello_registry, only: TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS, TRACK_PHASES
   use martello_run_quantities, only: C_CHATTER, PEAK_V, PEAK_A, PEAK_PEN, PEAK_FORCE, &
      PEAK_LINK_FORCE, PEAK_LINK_DU
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   implicit none

contains

   !> Peaks over every accepted state (after the step's phase changes): the node peaks
   !> (node_peaks) and, when the link states are given, the link peaks; on the steps of a
   !> fixed-step method given the previous state (u_prev …) also the extrema inside them: of
   !> u and v on every fixed step, of |a| (observer_a_parabolas) and of the links
   !> (link_step_peaks) on a smooth one. The contact maxima inside the steps are
   !> observer_penalty_phases'. The adaptive methods hand theirs (observer_extremum,
   !> observer_peak).
   module procedure track
      integer :: i
      logical :: stepped, raised
      stepped = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. t > o%prev_t .and. present(u_prev)
      if (.not. tracks(o, TRACK_NODE_PEAKS)) then
         ! nothing of the nodes
      else if (present(u_prev)) then
         if (stepped) call observer_a_parabolas(o, m, t, a, o%nsamples)
         do i = 1, size(u)
            call node_peaks(t, o%prev_t, o%fixed_steps, u_prev(i), v_prev(i), a_prev(i), u(i), &
                            v(i), a(i), o%u_max(i), o%u_min(i), o%v_absmax(i), o%a_absmax(i), &
                            o%u_absmax(i), o%t_absmax(i), o%u_peak(i), o%t_peak(i), raised)
            ! a candidate needs the sample two back (k − 2 ≥ 0, t = 0 being sample 0)
            if (raised .and. stepped .and. o%nsamples >= 2) &
               call a_candidate(o, i, a_prev(i), a(i), o%nsamples)
         end do
         if (o%smooth_steps) o%a_back(1:size(u)) = a_prev
      else
         ! no previous state (an adaptive method, which locates its own): the samples alone
         do i = 1, size(u)
            call node_peaks(t, -1.0_dp, .false., u(i), v(i), a(i), u(i), v(i), a(i), o%u_max(i), &
                            o%u_min(i), o%v_absmax(i), o%a_absmax(i), o%u_absmax(i), &
                            o%t_absmax(i), o%u_peak(i), o%t_peak(i), raised)
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
   end procedure track

   !> The peaks of a node at the accepted state (u, v, a) at t, the previous one (un, vn, an)
   !> at the last sample's time t_prev (< 0: none): extremes of u, |v|, |a| (umax … amax) and
   !> the largest |u| and its time (uabs, tabs) at the state; for a fixed-step method also
   !> the extrema of u and v located on the step's cubic Hermite (into the same and into the
   !> largest local maximum of u, upk at tpk: hermite_extremum, step_max). raised: the
   !> state raised amax (a candidate of observer_a_parabolas on a smooth method). The maxima
   !> are stored only when they change: a peak array is then read, not rewritten, at every
   !> step. observer_block takes its three parts in line.
   elemental subroutine node_peaks(t, t_prev, fixed_steps, un, vn, an, u, v, a, umax, umin, &
                                   vmax, amax, uabs, tabs, upk, tpk, raised)
      real(dp), intent(in) :: t, t_prev, un, vn, an, u, v, a
      logical, intent(in) :: fixed_steps
      real(dp), intent(inout) :: umax, umin, vmax, amax, uabs, tabs, upk, tpk
      logical, intent(out) :: raised
      call node_samples(t, u, v, a, umax, umin, vmax, amax, uabs, tabs, raised)
      if (.not. fixed_steps) return
      if (node_turns(vn, an, v, a)) &
         call node_step_extrema(t, t_prev, un, vn, an, u, v, a, umax, umin, vmax, uabs, tabs, &
                                upk, tpk)
   end subroutine node_peaks

   !> node_peaks at the state: extremes of u, |v|, |a| and the largest |u| at t; raised: the
   !> state raised amax.
   module procedure node_samples
      if (u > umax) umax = u
      if (u < umin) umin = u
      if (abs(v) > vmax) vmax = abs(v)
      raised = abs(a) > amax
      if (raised) amax = abs(a)
      call raise_absmax(uabs, tabs, t, u)
   end procedure node_samples

   !> Whether a fixed step from (vn, an) to (v, a) can hold an extremum of u (v changes sign,
   !> or reaches 0 from above) or of v (a changes sign): most steps of most nodes hold none.
   module procedure node_turns
      turns = vn*v < 0.0_dp .or. an*a < 0.0_dp .or. (vn > 0.0_dp .and. v == 0.0_dp)
   end procedure node_turns

   !> node_peaks inside a fixed step from the state (un, vn, an) at t_prev to (u, v, a) at t
   !> where node_turns (t_prev < 0: no step yet): the extrema of u and v on the step's cubic
   !> Hermite where the step resolves them (hermite_extremum, step_max), and a maximum of u
   !> on the step's end.
   module procedure node_step_extrema
      real(dp) :: h
      h = t - t_prev
      if (.not. (t_prev >= 0.0_dp .and. h > 0.0_dp)) return
      call hermite_extremum(t_prev, h, un, vn, an, u, v, a, umax, umin, uabs, tabs, upk, tpk)
      ! |v| at a maximum of v (and, of −v, at a minimum) on the cubic Hermite of (v, a), where
      ! the step resolves it (O(h⁴) in v; docs/results.md "Peaks of a fixed-step method")
      vmax = max(vmax, step_max(h, vn, an, v, a), step_max(h, -vn, -an, -v, -a))
      ! a maximum on the step's end
      if (vn > 0.0_dp .and. v == 0.0_dp .and. u > upk) then
         upk = u; tpk = t
      end if
   end procedure node_step_extrema

   !> The maxima of a contact at a sample: its largest δ and force (pen_max, force_max).
   module procedure contact_peaks
      if (pen > pen_max) pen_max = pen
      if (force > force_max) force_max = force
   end procedure contact_peaks

   !> The maxima of a contact's phase if open (ph_pen, ph_f) at a sample: as contact_peaks
   !> (after the phase change of the step, where the contact opens or closes).
   module procedure phase_peaks
      if (open) then
         ph_pen = max(ph_pen, pen); ph_f = max(ph_f, force)
      end if
   end procedure phase_peaks

   !> Whether the run tracks what (a TRACK_* bit).
   module procedure tracks
      tracks = iand(r%tracking, what) == what
   end procedure tracks

   !> A peak of kind (PEAK_*) of item j (node, contact or link) located by the method inside
   !> an accepted step, with value q (signed: |q| enters the node and link peaks; δ and the
   !> contact force their maxima and those of the open phase), into what the run tracks.
   module procedure observer_peak
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
   end procedure observer_peak

   !> The value a located peak of kind, j must exceed to change what is reported: the open
   !> phase's maximum for δ and the contact force (the run's otherwise), the run's peak for
   !> the others (|·|; 0 for a link not yet tracked); huge where the run tracks none of it.
   module procedure observer_peak_value
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
   end procedure observer_peak_value

   !> The number of items of a peak kind (0 for an unknown kind), tracked or not.
   module procedure peak_items
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
   end procedure peak_items

   !> An extremum of node i's displacement located by the method inside an accepted step, at t
   !> with value u (the root of the node's velocity on the stepper's own solution,
   !> docs/run-layer.md): folded into u_max, u_min, and for a maximum (maximum = .true.) into
   !> u_peak, t_peak.
   module procedure observer_extremum
      if (.not. tracks(o, TRACK_NODE_PEAKS)) return
      o%u_max(i) = max(o%u_max(i), u); o%u_min(i) = min(o%u_min(i), u)
      call raise_absmax(o%u_absmax(i), o%t_absmax(i), t, u)
      if (maximum .and. u > o%u_peak(i)) then
         o%u_peak(i) = u; o%t_peak(i) = t
      end if
   end procedure observer_extremum

   !> uabs, tabs ← |u|, t where |u| is larger (a node's u_absmax, t_absmax)
   elemental subroutine raise_absmax(uabs, tabs, t, u)
      real(dp), intent(inout) :: uabs, tabs
      real(dp), intent(in) :: t, u
      if (abs(u) > uabs) then
         uabs = abs(u); tabs = t
      end if
   end subroutine raise_absmax

   !> x ← max(x, y), the NaN x starts from replaced without comparing it (an ordered
   !> comparison with a NaN raises the invalid flag: a trap under -ffpe-trap=invalid)
   module procedure raise_to
      if (ieee_is_nan(x)) then
         x = y
      else if (x < y) then
         x = y
      end if
   end procedure raise_to

   !> The peak of |a| between the samples of a smooth fixed-step method, at sample number
   !> sample (t, a on nodes 1..n; before the sample's candidates, a_candidate): a sample k
   !> that raised it (a candidate) is the middle of the parabola through k − 1, k, k + 1,
   !> whose vertex (equal steps; inside the middle step when the middle sample is the
   !> largest) is O(h³) in a, below the O(h²) of the steps, if the samples resolve the
   !> turn: concave at each sample of the parabola's span (second differences of the
   !> crest's sign at k − 1, k and k + 1: the samples' p'' over the span, as the cubic's over
   !> a step, docs/results.md "Peaks of a fixed-step method"; a pulse of a few steps, as a
   !> wave front's 0, A, A, 0 at Courant 1, is convex at k − 1) and smooth: no jump of the
   !> forces (a phase change of a contact at the node, a chatter resolution, a kink of a
   !> load) from k − 1 to k + 2, and no kink — the second differences at k and k + 1 agree to
   !> half their size (a slope kink at the peak, as a bilinear spring's yield onto a flat
   !> line, makes them differ by O(h); its vertex would overshoot by O(h)). Candidates of
   !> sample k are completed here at k + 1 (a_p1) and decided at k + 2.
   module procedure observer_a_parabolas
      integer :: k, j
      integer(int8) :: s2, s1
      real(dp) :: ym2, ym, y0, yp, yq, d2, sg
      logical :: smooth
      s2 = stamp(sample - 2); s1 = stamp(sample - 1)
      if (o%npend2 > 0) then
         smooth = o%counters(C_CHATTER) == o%pend2_stamp .and. load_breakpoint(m, o%pend2_t0) > t
         do k = 1, o%npend2
            j = o%pend2(k)
            if (.not. smooth .or. o%a_gen(j) /= s2 .or. o%node_change(j) > o%pend2_t0) cycle
            sg = sign(1.0_dp, o%a_0(j))
            ym2 = sg*o%a_m2(j); ym = sg*o%a_m1(j); y0 = sg*o%a_0(j); yp = sg*o%a_p1(j)
            yq = sg*a(j)
            d2 = ym - 2.0_dp*y0 + yp
            if (.not. (y0 >= ym .and. y0 >= yp .and. d2 < 0.0_dp)) cycle
            if (.not. (ym2 - 2.0_dp*ym + y0 <= 0.0_dp)) cycle
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
   end procedure observer_a_parabolas

   !> Node j raised its sampled peak of |a| at sample number sample (≥ 2) of a smooth
   !> fixed-step method (node_peaks' raised), from a_prev at the sample before to a_now (the
   !> one before that: a_back): a candidate of observer_a_parabolas.
   subroutine a_candidate(o, j, a_prev, a_now, sample)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: j
      real(dp), intent(in) :: a_prev, a_now
      integer(i8), intent(in) :: sample
      o%npend1 = o%npend1 + 1; o%pend1(o%npend1) = j
      o%a_m2(j) = o%a_back(j); o%a_m1(j) = a_prev; o%a_0(j) = a_now; o%a_gen(j) = stamp(sample)
   end subroutine a_candidate

   !> A sample number modulo 256, as a_gen keeps it
   module procedure stamp
      stamp = int(modulo(sample, 256_i8) - 128_i8, int8)
   end procedure stamp

   !> The extremum of u inside a fixed step [t0, t0 + h], located on the cubic Hermite
   !> interpolant of (u, v) at both ends, p(s) = u0 H00 + h v0 H10 + u1 H01 + h v1 H11
   !> (s = τ/h): the root of p'(s), a quadratic, where v changes sign inside the step and the
   !> step resolves the turn: the cubic is concave over the step at a maximum, convex at a
   !> minimum (resolved_turn; docs/results.md "Peaks of a fixed-step method"); into umax,
   !> umin, uabs (tabs) and, a maximum, upk (tpk) — a maximum the step does not resolve is
   !> the larger value at its ends.
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
      if (v0 > 0.0_dp .and. .not. resolved_turn(h, u0, v0, u1, v1)) then
         ! a maximum the step does not resolve: the larger value at its ends
         if (max(u0, u1) > upk) then
            upk = max(u0, u1); tpk = merge(t0, t0 + h, u0 > u1)
         end if
         return
      end if
      if (v0 < 0.0_dp .and. .not. resolved_turn(h, -u0, -v0, -u1, -v1)) return
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
   pure module subroutine cubic_hermite_extrema(h, u0, v0, u1, v1, s, p)
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


   !> The peaks of every link inside a smooth fixed step of h from (un, vn, an) to (u, v, a)
   !> (nodes 1..n), f1 the link forces at its end (link_step_extremum): only a step where du̇
   !> (or, for a damper, dü) changes sign holds one.
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
         call link_step_extremum(m%link_kind(j), m%link_par(:, j), h, &
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
   !> The general path takes it for every link, observer_block for a method's bilinear links
   !> (its linear ones: step_absmax per node and pair, the same numbers).
   module procedure link_step_extremum
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
   end procedure link_step_extremum

   !> The maxima of a contact inside a smooth fixed step of h from its state at the start
   !> (δ = d0, δ̇ = r0, force f0 and its rate fr0) to that at the end (d1, r1, f1, fr1):
   !> where δ > 0 at both ends, dm, the largest δ on the cubic Hermite of (δ, δ̇), and where
   !> the law pushes at both ends (a clipped Kelvin past its cut-off, or a contact the
   !> chatter rule holds open, does not), fm, that of the force on the cubic Hermite of
   !> (P, Ṗ); −huge where there is none. O(h⁴) in the value where the law is smooth over the
   !> step (docs/results.md).
   module procedure step_maxima
      dm = -huge(1.0_dp); fm = -huge(1.0_dp)
      if (.not. (d0 > 0.0_dp .and. d1 > 0.0_dp)) return
      dm = step_max(h, d0, r0, d1, r1)
      if (f0 > 0.0_dp .and. f1 > 0.0_dp) fm = step_max(h, f0, fr0, f1, fr1)
   end procedure step_maxima

   !> The largest value inside a step of h of the cubic Hermite of (q, q̇) at both ends (q0,
   !> r0 at the start, q1, r1 at the end) where the rate turns from > 0 to < 0 and the step
   !> resolves the turn: the cubic is concave over the step (resolved_turn); −huge where
   !> none (the values at the steps stand).
   elemental real(dp) function step_max(h, q0, r0, q1, r1) result(x)
      real(dp), intent(in) :: h, q0, r0, q1, r1
      real(dp) :: s(2), p(2)
      integer :: k
      x = -huge(1.0_dp)
      if (.not. (r0 > 0.0_dp .and. r1 < 0.0_dp)) return
      if (.not. resolved_turn(h, q0, r0, q1, r1)) return
      call cubic_hermite_extrema(h, q0, r0, q1, r1, s, p)
      do k = 1, 2
         if (s(k) > 0.0_dp .and. s(k) < 1.0_dp) x = max(x, p(k))
      end do
   end function step_max

   !> Whether the cubic Hermite of (q, q̇) on a step of h (q0, r0 at the start, q1, r1 at the
   !> end) is concave over the step: p'' ≤ 0 at both ends (p'' is linear), i.e. the secant
   !> slope in the middle third from r1 to r0, h p''(0) = 6(q1 − q0)/h − 4r0 − 2r1 ≤ 0 and
   !> h p''(h) = −6(q1 − q0)/h + 2r0 + 4r1 ≤ 0 (docs/results.md, "Peaks of a fixed-step
   !> method"). A maximum the step resolves is concave around it on a scale well above the
   !> step (a sine's cubic is concave over any step holding its crest up to ωh ≈ 1.5); where
   !> p'' changes sign inside the step, |p''| ≤ h|p'''| over it, so the crest rises above the
   !> ends by O(h³ p''') — below the steps' own O(h²) error where the data are smooth, and the
   !> data's own jump where they are not (a force that steps onto a plateau at Courant 1: the
   !> cubic makes 4/27 of the jump out of the mean of the half-step velocities). Such a crest
   !> is the interpolant's, not the method's: the values at the steps stand.
   elemental logical function resolved_turn(h, q0, r0, q1, r1)
      real(dp), intent(in) :: h, q0, r0, q1, r1
      real(dp) :: dq
      dq = 3.0_dp*(q1 - q0)
      resolved_turn = dq <= h*(2.0_dp*r0 + r1) .and. dq >= h*(r0 + 2.0_dp*r1)
   end function resolved_turn

   !> The largest |value| inside a step of h of the cubic Hermite of (q, q̇) at both ends
   !> where the rate changes sign; 0 where none (a link's elongation, a dashpot's rate:
   !> observer_block's per node and pair maxima, as link_step_extremum).
   module procedure step_absmax
      real(dp) :: s(2), p(2)
      integer :: k
      x = 0.0_dp
      if (.not. (r0*r1 < 0.0_dp)) return
      call cubic_hermite_extrema(h, q0, r0, q1, r1, s, p)
      do k = 1, 2
         if (s(k) > 0.0_dp .and. s(k) < 1.0_dp) x = max(x, abs(p(k)))
      end do
   end procedure step_absmax
end submodule peaks
