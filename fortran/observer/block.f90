!> The observer's bulk entry (docs/run-layer.md "A method that measures itself"): the state
!> of a method that holds its scene per node — nodes in a row, the contacts between
!> neighbours, the other items one by one (node_block_t) — measured a block of nodes at a
!> time, with the procedures of the general path (node peaks, the located extrema inside the
!> step, the contacts' phases and maxima). The method hands states only; the passes run on
!> the observer's own arrays, handed to them as arrays (nothing else in the call reaches
!> them: no aliasing), and what needs the observer whole (a phase change, an event row) is
!> listed by the pass and done after it.
submodule (martello_observer) block
   use martello_model, only: model_link_at, model_contact_at, model_nlinks, model_ncontacts, &
      model_link_index
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP
   use martello_element_rows, only: row_a, row_b
   use martello_contact_laws, only: LAW_KELVIN, P_STIFF, P_DAMPING, P_CLIP, BRANCH_OFF, &
      BRANCH_ON, AFFINE_LINEAR, AFFINE_KELVIN_CLIPPED, NPAR_CONTACT
   use martello_registry, only: TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS, TRACK_PHASES
   implicit none

   !> Phase changes a pass over the pair contacts lists before they are handed over (then it
   !> goes on): the size of its list, on the stack
   integer, parameter :: CHANGES = 256

contains

   !> The state at t = t_k of a method that measures itself (k: the grid point), a fixed
   !> step of h from the previous sample (0 at t = 0): every node's peaks, every contact's
   !> phases and maxima and the link maxima, each with its extrema inside the step located
   !> as the general path locates them (docs/results.md); then the sample (energies, where
   !> observer_energy_due, from the method; the history row; the divergence test). un … the
   !> state at the previous sample, u … this one (nodes 0:n); br: the committed branch of
   !> each pair contact (BRANCH_*; 0:n), xbr of each other contact; bf, bdu: the committed
   !> force and elongation of each bilinear link (blk).
   module procedure observer_block
      type(mech_state_t) :: none
      real(dp), allocatable :: pen(:), force(:), lf(:), ld(:)
      integer :: n, p, nch, st, changed(CHANGES)
      logical :: loc
      n = size(u) - 1
      loc = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. t > o%prev_t
      ! the candidates of |a| decided (or completed) with this sample's a, before its own
      if (loc .and. tracks(o, TRACK_NODE_PEAKS)) &
         call observer_a_parabolas(o, m, t, a(1:n), o%nsamples + 1)
      if (tracks(o, TRACK_NODE_PEAKS) .or. size(o%gu) + size(o%gv) + size(o%pu) + size(o%pv) > 0) &
         call node_pass(n, t, o%prev_t, o%fixed_steps, loc, loc .and. o%nsamples + 1 >= 2, &
                        o%smooth_steps, tracks(o, TRACK_NODE_PEAKS), &
                        size(o%gu) > 0, size(o%gv) > 0, size(o%pu) > 0, size(o%pv) > 0, &
                        stamp(o%nsamples + 1), un, vn, an, u, v, a, o%u_max, o%u_min, &
                        o%v_absmax, o%a_absmax, o%u_absmax, o%t_absmax, o%u_peak, o%t_peak, &
                        o%gu, o%gv, o%pu, o%pv, o%a_back, o%a_m2, o%a_m1, o%a_0, o%a_gen, &
                        o%pend1, o%npend1)
      if (blk%pairs) then
         p = 1
         do while (p < n)
            call pair_pass(p, n, t - o%prev_t, loc, h > 0.0_dp, tracks(o, TRACK_CONTACT_PEAKS), &
                           tracks(o, TRACK_PHASES), blk%kelvin, blk%first, blk%number, blk%ss, &
                           blk%sg, blk%sk, blk%sc, blk%sl, blk%sgn, blk%gap, blk%k, blk%c, blk%law, &
                           br, un, vn, an, u, v, a, o%pen_max, o%force_max, o%ph_open, o%ph_pen, &
                           o%ph_f, changed, nch)
            if (nch > 0) call pair_changes(o, blk, n, changed(1:nch), t, h, un, vn, an, u, v, a, br)
         end do
      end if
      call other_contacts(o, m, t, h, loc, blk, un, vn, an, u, v, a, xbr)
      if (tracks(o, TRACK_LINK_PEAKS)) call bilinear_links(o, m, t - o%prev_t, loc, blk, un, vn, v, &
                                                           bf, bdu)
      ! the history's contact and link columns, at its rows alone (none: no entries)
      allocate (pen(0), force(0), stat=st)
      if (recorded(o, k)) then
         if (st == 0 .and. size(o%out_contacts) > 0) &
            call contact_states(m, blk, o%out_contacts, u, v, br, xbr, pen, force, st)
         if (st == 0 .and. size(o%out_links) > 0) &
            call link_states(m, blk, o%out_links, u, v, bf, lf, ld, st)
      end if
      ! the traced contact's force at every grid point (the step trace)
      if (st == 0 .and. traced(o, k)) call traced_force(st)
      if (st /= 0) then
         call out_of_memory('the recorded contact and link states of a run', &
                            REAL_BYTES*2*(model_ncontacts(m) + real(model_nlinks(m), dp)), &
                            FIX_SMALLER_SCENE, stat, o%message)
         call observer_failed(o, t, stat); return
      end if
      call observer_sample(o, m, none, t, u, v, a, pen, force, k, stat, lf, ld, folded=.true., &
                           energies=energies)
   contains
      !> o%trace_f ← the traced contact's force at the state (contact_states, as its
      !> history column)
      subroutine traced_force(st)
         integer, intent(out) :: st
         real(dp), allocatable :: p1(:), f1(:)
         allocate (p1(0), f1(0))
         call contact_states(m, blk, [o%trace_contact], u, v, br, xbr, p1, f1, st)
         if (st == 0) o%trace_f = f1(o%trace_contact)
      end subroutine traced_force
   end procedure observer_block

   !> observer_block's nodes and node pairs, one pass: a node's peaks (node_samples at the
   !> state; node_step_extrema where node_turns: v or a changes sign in the step, which most
   !> nodes do in few steps; a node that raised its |a| listed in pend as a candidate of
   !> observer_a_parabolas, stamped sgen, where cand: a located step two samples after
   !> t = 0; a_back: every node's a of the sample before, where smooth), and the link
   !> maxima per node (gu, gv: |u|, |v|) and per pair (pu, pv: |Δu|, |Δv|), inside the step
   !> too (step_absmax where the rate changes sign). nodes, gu_on …: what is tracked; loc:
   !> the extrema inside the step from t_prev.
   subroutine node_pass(n, t, t_prev, fs, loc, cand, smooth, nodes, gu_on, gv_on, pu_on, pv_on, &
                        sgen, un, vn, an, u, v, a, umax, umin, vmax, amax, uabs, tabs, upk, tpk, &
                        gu, gv, pu, pv, a_back, a_m2, a_m1, a_0, a_gen, pend, npend)
      integer, intent(in), value :: n
      real(dp), intent(in), value :: t, t_prev
      logical, intent(in), value :: fs, loc, cand, smooth, nodes, gu_on, gv_on, pu_on, pv_on
      integer(int8), intent(in), value :: sgen
      real(dp), intent(in) :: un(0:n), vn(0:n), an(0:n), u(0:n), v(0:n), a(0:n)
      real(dp), intent(inout) :: umax(*), umin(*), vmax(*), amax(*), uabs(*), tabs(*), upk(*), &
                                 tpk(*), gu(*), gv(*), pu(*), pv(*), a_back(*), a_m2(*), &
                                 a_m1(*), a_0(*)
      integer(int8), intent(inout) :: a_gen(*)
      integer, intent(inout) :: pend(*), npend
      integer :: i, p
      real(dp) :: hl, x, du, dv, dvn
      logical :: raised, turns, find
      hl = t - t_prev                    ! the step the extrema are located on
      find = loc .and. (nodes .or. gu_on .or. gv_on)
      do i = 1, n
         ! the node's v or a changes sign in the step (rare): its extrema inside it
         turns = .false.
         if (find) turns = node_turns(vn(i), an(i), v(i), a(i))
         if (nodes) then
            call node_samples(t, u(i), v(i), a(i), umax(i), umin(i), vmax(i), amax(i), uabs(i), &
                              tabs(i), raised)
            if (turns .and. fs) call node_step_extrema(t, t_prev, un(i), vn(i), an(i), u(i), v(i), &
                                                       a(i), umax(i), umin(i), vmax(i), uabs(i), &
                                                       tabs(i), upk(i), tpk(i))
            if (raised .and. cand) then
               npend = npend + 1; pend(npend) = i
               a_m2(i) = a_back(i); a_m1(i) = an(i); a_0(i) = a(i); a_gen(i) = sgen
            end if
            if (smooth) a_back(i) = an(i)
         end if
         ! the maxima stored only when they change (read, not rewritten, at every step)
         if (gu_on) then
            x = abs(u(i))
            if (turns) then
               if (vn(i)*v(i) < 0.0_dp) x = max(x, step_absmax(hl, un(i), vn(i), u(i), v(i)))
            end if
            if (x > gu(i)) gu(i) = x
         end if
         if (gv_on) then
            x = abs(v(i))
            if (turns) then
               if (an(i)*a(i) < 0.0_dp) x = max(x, step_absmax(hl, vn(i), an(i), v(i), a(i)))
            end if
            if (x > gv(i)) gv(i) = x
         end if
      end do
      ! the pairs (p, p + 1), in a loop of their own (a chain has no links between nodes)
      if (.not. (pu_on .or. pv_on)) return
      do p = 1, n - 1
         i = p + 1
         if (pu_on) then
            du = u(p) - u(i); dv = v(p) - v(i); dvn = vn(p) - vn(i)
            x = abs(du)
            if (loc .and. dvn*dv < 0.0_dp) x = max(x, step_absmax(hl, un(p) - un(i), dvn, du, dv))
            if (x > pu(p)) pu(p) = x
         end if
         if (pv_on) then
            dv = v(p) - v(i); dvn = vn(p) - vn(i)
            x = abs(dv)
            if (loc .and. (an(p) - an(i))*(a(p) - a(i)) < 0.0_dp) &
               x = max(x, step_absmax(hl, dvn, an(p) - an(i), dv, a(p) - a(i)))
            if (x > pv(p)) pv(p) = x
         end if
      end do
   end subroutine node_pass

   !> observer_block's pair contacts from p to n − 1, one pass: each one's maxima, at the
   !> state and, while its phase spans the step (open before and after it, δ > 0 at both
   !> ends), inside it (step_maxima: the force and its rate at the start computed again from
   !> the state there), and its open phase's maxima. A pair whose phase changes in the step
   !> is listed in changed (nch of them) for pair_changes. hl: the step from the previous
   !> sample; step: there is one. A contact open before and after the step (most of them,
   !> most steps) costs its δ and one comparison in a scan that lists the others (busy: at
   !> most CHANGES, where the pass stops; p: where to go on), each then closed_pair's; the
   !> scan takes the chain of one kind (every pair a contact numbered in order, one sign
   !> and gap) in a loop of its own.
   subroutine pair_pass(p, n, hl, loc, step, contacts, phases, kel, first, number, ss, sg, sk, &
                        sc, sl, sgn, gap, kk, cc, law, br, un, vn, an, u, v, a, pen_max, &
                        force_max, ph_open, ph_pen, ph_f, changed, nch)
      integer, intent(inout) :: p
      integer, intent(in), value :: n, first, ss, sg, sk, sc, sl
      real(dp), intent(in), value :: hl
      logical, intent(in), value :: loc, step, contacts, phases, kel
      integer, intent(in) :: number(0:*)
      real(dp), intent(in) :: sgn(0:*), gap(0:*), kk(0:*), cc(0:*)
      integer(int8), intent(in) :: law(0:*), br(0:n)
      real(dp), intent(in) :: un(0:n), vn(0:n), an(0:n), u(0:n), v(0:n), a(0:n)
      real(dp), intent(inout) :: pen_max(*), force_max(*), ph_pen(*), ph_f(*)
      logical, intent(in) :: ph_open(*)
      integer, intent(out) :: changed(CHANGES), nch
      integer :: q, j, nb, busy(CHANGES)
      real(dp) :: s, gp
      nch = 0
      call scan_pairs(p, n, first, number, ss, sg, sgn, gap, contacts, br, u, ph_open, pen_max, &
                      busy, nb)
      do j = 1, nb
         q = busy(j); s = sgn(q*ss); gp = gap(q*sg)
         call closed_pair(q, contact_of(q), s, gp, s*(u(q) - u(q + 1)) - gp)
      end do
   contains
      !> The contact of pair q (0: none).
      integer function contact_of(q) result(c)
         integer, intent(in) :: q
         if (first >= 0) then
            c = first + q
         else
            c = number(q)
         end if
      end function contact_of

      !> pair q (contact c, its sign s and gap gp; δ = pen at the state) closed at the start or
      !> the end of the step
      subroutine closed_pair(q, c, s, gp, pen)
         integer, intent(in) :: q, c
         real(dp), intent(in) :: s, gp, pen
         integer :: i
         integer(int8) :: lw
         real(dp) :: f, kp, cp, d0, r0, q0, r1, q1, f0, fr0, fr1, dm, fm
         logical :: on, was
         i = q + 1
         kp = kk(q*sk); cp = 0.0_dp; lw = AFFINE_LINEAR
         if (kel) then
            lw = law(q*sl)
            if (lw /= AFFINE_LINEAR) cp = cc(q*sc)
         end if
         f = 0.0_dp
         if (br(q) == BRANCH_ON) then
            f = kp*pen
            if (lw /= AFFINE_LINEAR) f = f + cp*(s*(v(q) - v(i)))
         end if
         on = br(q) /= BRANCH_OFF
         was = ph_open(c)
         if (step .and. (on .neqv. was)) then
            ! its phase opens or closes (pair_changes); its run maxima at the state here
            if (contacts) call contact_peaks(pen, f, pen_max(c), force_max(c))
            nch = nch + 1; changed(nch) = q
            return
         end if
         if (on .and. was .and. loc .and. (contacts .or. phases) .and. pen > 0.0_dp) then
            ! a phase over the whole step: its maxima inside it, where δ or the force turns
            ! from rising to falling in it (the rate at the end < 0: else there is none)
            r1 = s*(v(q) - v(i)); q1 = s*(a(q) - a(i))
            fr1 = 0.0_dp
            if (f > 0.0_dp) fr1 = kp*r1 + cp*q1
            if (r1 < 0.0_dp .or. fr1 < 0.0_dp) then
               d0 = s*(un(q) - un(i)) - gp
               if (d0 > 0.0_dp) then
                  r0 = s*(vn(q) - vn(i)); q0 = s*(an(q) - an(i))
                  f0 = kp*d0
                  if (lw /= AFFINE_LINEAR) f0 = f0 + cp*r0
                  if (lw == AFFINE_KELVIN_CLIPPED .and. f0 <= 0.0_dp) f0 = 0.0_dp
                  fr0 = 0.0_dp
                  if (f0 > 0.0_dp) fr0 = kp*r0 + cp*q0
                  call step_maxima(hl, d0, r0, f0, fr0, pen, r1, f, fr1, dm, fm)
                  if (contacts) call contact_peaks(dm, fm, pen_max(c), force_max(c))
                  if (phases) call phase_peaks(.true., dm, fm, ph_pen(c), ph_f(c))
               end if
            end if
         end if
         if (phases) call phase_peaks(on, pen, f, ph_pen(c), ph_f(c))
         if (contacts) call contact_peaks(pen, f, pen_max(c), force_max(c))
      end subroutine closed_pair
   end subroutine pair_pass

   !> pair_pass's scan of the pairs from p to n − 1 (their contacts, signs and gaps as
   !> there): a contact open before and after the step has its run maximum raised (where
   !> contacts are tracked); the others are listed in busy (nb of them) up to CHANGES, where
   !> the scan stops (p: where to go on). Small and apart, so that its loop keeps what it
   !> reads in registers; the chain of one kind in a loop of its own (one_kind).
   subroutine scan_pairs(p, n, first, number, ss, sg, sgn, gap, contacts, br, u, ph_open, &
                         pen_max, busy, nb)
      integer, intent(inout) :: p
      integer, intent(in), value :: n, first, ss, sg
      logical, intent(in), value :: contacts
      integer, intent(in) :: number(0:*)
      real(dp), intent(in) :: sgn(0:*), gap(0:*), u(0:n)
      integer(int8), intent(in) :: br(0:n)
      logical, intent(in) :: ph_open(*)
      real(dp), intent(inout) :: pen_max(*)
      integer, intent(out) :: busy(CHANGES), nb
      integer :: q, c
      nb = 0
      if (first >= 0 .and. ss == 0 .and. sg == 0) then
         call one_kind(p, n, first, sgn(0), gap(0), contacts, br, u, ph_open, pen_max, busy, nb)
         return
      end if
      do q = p, n - 1
         c = first + q
         if (first < 0) c = number(q)
         if (c == 0) cycle
         if (stays_open(br(q), ph_open(c), sgn(q*ss)*(u(q) - u(q + 1)) - gap(q*sg), contacts, &
                        pen_max(c))) cycle
         if (list_full(q, busy, nb)) exit
      end do
      p = min(q + 1, n)
   end subroutine scan_pairs

   !> scan_pairs on a chain of one kind: every pair q a contact, first + q, of sign s and
   !> gap gp; its phase and run maximum are open(q) and pmax(q) (the observer's ph_open and
   !> pen_max from their element 1 − first: no index sum in the loop).
   subroutine one_kind(p, n, first, s, gp, contacts, br, u, open, pmax, busy, nb)
      integer, intent(inout) :: p, nb
      integer, intent(in), value :: n, first
      real(dp), intent(in), value :: s, gp
      logical, intent(in), value :: contacts
      integer(int8), intent(in) :: br(0:n)
      real(dp), intent(in) :: u(0:n)
      logical, intent(in) :: open(1 - first:*)
      real(dp), intent(inout) :: pmax(1 - first:*)
      integer, intent(inout) :: busy(CHANGES)
      integer(i8) :: q                  ! (the loop then keeps no default-integer copy of it)
      do q = p, n - 1
         if (stays_open(br(q), open(q), s*(u(q) - u(q + 1)) - gp, contacts, pmax(q))) cycle
         if (list_full(int(q), busy, nb)) exit
      end do
      p = int(min(q + 1, int(n, i8)))
   end subroutine one_kind

   !> A pair contact on branch b whose phase was open (was), δ = pen at the state: whether
   !> it stays open over the step (open before and after it); its run maximum pmax raised
   !> then, where tracked (contacts).
   logical function stays_open(b, was, pen, contacts, pmax) result(open)
      integer(int8), intent(in) :: b
      logical, intent(in) :: was, contacts
      real(dp), intent(in) :: pen
      real(dp), intent(inout) :: pmax
      open = b == BRANCH_OFF .and. .not. was
      if (open .and. contacts) then
         if (pen > pmax) pmax = pen
      end if
   end function stays_open

   !> Pair q listed in busy (nb entries); whether the list is full.
   logical function list_full(q, busy, nb) result(full)
      integer, intent(in) :: q
      integer, intent(inout) :: busy(CHANGES), nb
      nb = nb + 1; busy(nb) = q
      full = nb == CHANGES
   end function list_full

   !> The phase changes of the pair contacts pair_pass listed (pairs, nodes p, p + 1) in the
   !> step (t − h, t], handed over as one list: each located on the free side of the step
   !> from its δ, δ̇, δ̈ at both ends (phase_change), then its open phase's maxima at the
   !> state.
   subroutine pair_changes(o, blk, n, pairs, t, h, un, vn, an, u, v, a, br)
      type(observer_t), intent(inout) :: o
      type(node_block_t), intent(in) :: blk
      integer, intent(in) :: n, pairs(:)
      real(dp), intent(in) :: t, h, un(0:n), vn(0:n), an(0:n), u(0:n), v(0:n), a(0:n)
      integer(int8), intent(in) :: br(0:n)
      integer :: j, p, c, i
      real(dp) :: s, gp, pen, f
      logical :: on, phases
      phases = tracks(o, TRACK_PHASES)
      do j = 1, size(pairs)
         p = pairs(j); i = p + 1
         c = pair_number(blk, p)
         s = blk%sgn(p*blk%ss); gp = blk%gap(p*blk%sg)
         pen = s*(u(p) - u(i)) - gp
         f = 0.0_dp
         if (br(p) == BRANCH_ON) then
            f = blk%k(p*blk%sk)*pen
            if (blk%kelvin) then
               if (blk%law(p*blk%sl) /= AFFINE_LINEAR) f = f + blk%c(p*blk%sc)*(s*(v(p) - v(i)))
            end if
         end if
         on = br(p) /= BRANCH_OFF
         call phase_change(o, c, on, pen, f, s*(un(p) - un(i)) - gp, s*(vn(p) - vn(i)), &
                           s*(an(p) - an(i)), pen, s*(v(p) - v(i)), s*(a(p) - a(i)), t, h, [p, i])
         if (phases) call phase_peaks(on, pen, f, o%ph_pen(c), o%ph_f(c))
      end do
   end subroutine pair_changes

   !> The method's other contacts, one by one (the model's linear and Kelvin laws on their
   !> committed branches xbr), as the pair contacts: maxima inside the step while the phase
   !> spans it (the start's force by the whole law), phase changes, maxima at the state.
   subroutine other_contacts(o, m, t, h, loc, blk, un, vn, an, u, v, acc, xbr)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t, h
      logical, intent(in) :: loc
      type(node_block_t), intent(in) :: blk
      real(dp), intent(in) :: un(0:), vn(0:), an(0:), u(0:), v(0:), acc(0:)
      integer(int8), intent(in) :: xbr(:)
      integer :: idx, j, a, b, c
      real(dp) :: pen, f, r1, d0, r0, f0, fr0, fr1, kc, cc
      logical :: on
      do idx = 1, size(blk%xg)
         j = blk%xg(idx); a = row_a(m%con, j); b = row_b(m%con, j); c = blk%xc(idx)
         pen = u(a) - u(b) - m%con_gap(j); r1 = v(a) - v(b)
         on = xbr(idx) /= BRANCH_OFF
         f = 0.0_dp
         if (xbr(idx) == BRANCH_ON) f = affine_force(m, j, pen, r1, .false.)
         d0 = un(a) - un(b) - m%con_gap(j)
         if (loc .and. o%ph_open(c) .and. on .and. d0 > 0.0_dp .and. &
             (tracks(o, TRACK_CONTACT_PEAKS) .or. tracks(o, TRACK_PHASES))) then
            r0 = vn(a) - vn(b)
            f0 = 0.0_dp
            if (d0 > 0.0_dp) f0 = affine_force(m, j, d0, r0, .true.)
            kc = m%con_par(P_STIFF, j); cc = 0.0_dp
            if (m%con_law(j) == LAW_KELVIN) cc = m%con_par(P_DAMPING, j)
            fr0 = 0.0_dp; fr1 = 0.0_dp
            if (f0 > 0.0_dp) fr0 = kc*r0 + cc*(an(a) - an(b))
            if (f > 0.0_dp) fr1 = kc*r1 + cc*(acc(a) - acc(b))
            call contact_step_peaks(o, c, t - o%prev_t, d0, r0, f0, fr0, pen, r1, f, fr1)
         end if
         if (h > 0.0_dp .and. (on .neqv. o%ph_open(c))) &
            call phase_change(o, c, on, pen, f, d0, vn(a) - vn(b), an(a) - an(b), pen, r1, &
                              acc(a) - acc(b), t, h, [a, b])
         if (tracks(o, TRACK_PHASES)) call phase_peaks(o%ph_open(c), pen, f, o%ph_pen(c), o%ph_f(c))
         if (tracks(o, TRACK_CONTACT_PEAKS)) call contact_peaks(pen, f, o%pen_max(c), o%force_max(c))
      end do
   end subroutine other_contacts

   !> The force of contact j added one by one (linear or Kelvin) at δ = pen, δ̇ = rate on the
   !> branch that pushes; clip: the Kelvin law's cut-off at 0 applies (the whole law).
   real(dp) function affine_force(m, j, pen, rate, clip) result(f)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: pen, rate
      logical, intent(in) :: clip
      f = m%con_par(P_STIFF, j)*pen
      if (m%con_law(j) == LAW_KELVIN) then
         f = f + m%con_par(P_DAMPING, j)*rate
         if (clip .and. m%con_par(P_CLIP, j) > 0.5_dp .and. f <= 0.0_dp) f = 0.0_dp
      end if
   end function affine_force

   !> The method's bilinear links at their committed force bf and elongation bdu, and inside
   !> the step of hl (link_step_extremum).
   subroutine bilinear_links(o, m, hl, loc, blk, un, vn, v, bf, bdu)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: hl
      logical, intent(in) :: loc
      type(node_block_t), intent(in) :: blk
      real(dp), intent(in) :: un(0:), vn(0:), v(0:), bf(:), bdu(:)
      integer :: idx, j, l, a, b
      do idx = 1, size(blk%blo)
         j = blk%blo(idx); l = blk%bl(idx); a = row_a(m%lnk, l); b = row_b(m%lnk, l)
         call raise_to(o%link_force_absmax(j), abs(bf(idx)))
         call raise_to(o%link_du_absmax(j), abs(bdu(idx)))
         if (loc) call link_step_extremum(LINK_BILINEAR, m%link_par(:, l), hl, un(a) - un(b), &
                                          vn(a) - vn(b), 0.0_dp, bdu(idx), v(a) - v(b), 0.0_dp, &
                                          bf(idx), o%link_force_absmax(j), o%link_du_absmax(j))
      end do
   end subroutine bilinear_links

   !> δ and force of the contacts which (0 elsewhere): the history's columns.
   subroutine contact_states(m, blk, which, u, v, br, xbr, pen, force, st)
      type(model_t), intent(in) :: m
      type(node_block_t), intent(in) :: blk
      integer, intent(in) :: which(:)
      real(dp), intent(in) :: u(0:), v(0:)
      integer(int8), intent(in) :: br(0:), xbr(:)
      real(dp), allocatable, intent(inout) :: pen(:), force(:)
      integer, intent(out) :: st
      integer :: idx, j, i, a, b, scheme, law, p
      integer(int8) :: on
      real(dp) :: gap, par(NPAR_CONTACT), c
      deallocate (pen, force)
      allocate (pen(model_ncontacts(m)), force(model_ncontacts(m)), stat=st)
      if (st /= 0) return
      pen = 0.0_dp; force = 0.0_dp
      do idx = 1, size(which)
         j = which(idx)
         call model_contact_at(m, j, a, b, gap, scheme, law, par)
         pen(j) = u(a) - u(b) - gap
         ! its committed branch and damping: a pair contact's or another's
         on = BRANCH_OFF; c = 0.0_dp
         if (a > 0 .and. b > 0) then
            p = min(a, b)
            if (pair_number(blk, p) == j) then
               on = br(p); c = blk%c(p*blk%sc)
            end if
         end if
         do i = 1, size(blk%xc)
            if (blk%xc(i) == j) then
               on = xbr(i); c = m%con_par(P_DAMPING, blk%xg(i))
            end if
         end do
         if (on == BRANCH_ON) force(j) = par(P_STIFF)*pen(j)
         if (on == BRANCH_ON .and. law == LAW_KELVIN) force(j) = force(j) + c*(v(a) - v(b))
      end do
   end subroutine contact_states

   !> The contact of pair (p, p + 1) (0: none).
   pure integer function pair_number(blk, p) result(c)
      type(node_block_t), intent(in) :: blk
      integer, intent(in) :: p
      if (.not. blk%pairs) then
         c = 0
      else if (blk%first >= 0) then
         c = blk%first + p
      else
         c = blk%number(p)
      end if
   end function pair_number

   !> Force and elongation of the links which (0 elsewhere): the history's columns.
   subroutine link_states(m, blk, which, u, v, bf, lf, ld, st)
      type(model_t), intent(in) :: m
      type(node_block_t), intent(in) :: blk
      integer, intent(in) :: which(:)
      real(dp), intent(in) :: u(0:), v(0:), bf(:)
      real(dp), allocatable, intent(out) :: lf(:), ld(:)
      integer, intent(out) :: st
      integer :: idx, j, a, b, q, kind
      real(dp) :: par(NPAR_LINK)
      allocate (lf(model_nlinks(m)), ld(model_nlinks(m)), stat=st)
      if (st /= 0) return
      lf = 0.0_dp; ld = 0.0_dp
      do idx = 1, size(which)
         j = which(idx)
         call model_link_at(m, j, kind, a, b, par)
         ld(j) = u(a) - u(b)
         select case (kind)
         case (LINK_DASHPOT)
            lf(j) = par(L_DAMP)*(v(a) - v(b))
         case (LINK_BILINEAR)
            do q = 1, size(blk%blo)
               if (blk%blo(q) == j) lf(j) = bf(q)
            end do
         case default
            lf(j) = par(L_STIFF)*ld(j)
         end select
      end do
   end subroutine link_states

   !> The link maxima per node and pair of a method that measures itself (observer_begin):
   !> for the kinds of linear links the scene has, where link peaks are tracked.
   module procedure block_maxima
      integer :: j, n
      logical :: ground, gdamp, pair, pdamp
      n = merge(m%n, 0, tracks(o, TRACK_LINK_PEAKS))
      ground = .false.; gdamp = .false.; pair = .false.; pdamp = .false.
      do j = 1, m%nlink
         if (m%link_kind(j) == LINK_BILINEAR) cycle
         if (row_a(m%lnk, j) > 0 .and. row_b(m%lnk, j) > 0) then
            pair = .true.; pdamp = pdamp .or. m%link_kind(j) == LINK_DASHPOT
         else
            ground = .true.; gdamp = gdamp .or. m%link_kind(j) == LINK_DASHPOT
         end if
      end do
      do j = 1, m%nchain
         ground = .true.
         if (allocated(m%chain(j)%c)) gdamp = gdamp .or. any(m%chain(j)%c > 0.0_dp)
      end do
      allocate (o%gu(merge(n, 0, ground)), o%gv(merge(n, 0, gdamp)), o%pu(merge(n, 0, pair)), &
                o%pv(merge(n, 0, pdamp)), source=0.0_dp, stat=st)
   end procedure block_maxima

   !> The end of a run, whatever its method and outcome: every linear link's peaks of a
   !> method that measured itself, from the maxima of its node or pair (observer_block):
   !> |f| = |k|·max|Δu| of a spring or bar, |c|·max|Δv| of a dashpot (rounding is monotone:
   !> the same numbers as the largest |k Δu| over the samples).
   module procedure observer_close
      integer :: j, a, b, q, i, idx
      real(dp) :: umax, vmax
      if (.not. (allocated(o%gu) .and. tracks(o, TRACK_LINK_PEAKS) .and. o%nsamples >= 0)) return
      do j = 1, m%nlink
         a = row_a(m%lnk, j); b = row_b(m%lnk, j)
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT)
         case default
            cycle
         end select
         vmax = 0.0_dp
         if (a > 0 .and. b > 0) then
            umax = o%pu(min(a, b))
            if (m%link_kind(j) == LINK_DASHPOT) vmax = o%pv(min(a, b))
         else
            umax = o%gu(a + b)
            if (m%link_kind(j) == LINK_DASHPOT) vmax = o%gv(a + b)
         end if
         idx = model_link_index(m, j)
         o%link_du_absmax(idx) = umax
         if (m%link_kind(j) == LINK_DASHPOT) then
            o%link_force_absmax(idx) = abs(m%link_par(L_DAMP, j))*vmax
         else
            o%link_force_absmax(idx) = abs(m%link_par(L_STIFF, j))*umax
         end if
      end do
      ! a chain's: the spring, then (where c > 0) the dashpot of each node
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            idx = ch%link0
            do i = 1, ch%n
               j = ch%first + i - 1
               idx = idx + 1
               o%link_du_absmax(idx) = o%gu(j)
               o%link_force_absmax(idx) = abs(ch%k(i))*o%gu(j)
               if (.not. allocated(ch%c)) cycle
               if (.not. (ch%c(i) > 0.0_dp)) cycle
               idx = idx + 1
               o%link_du_absmax(idx) = o%gu(j)
               o%link_force_absmax(idx) = ch%c(i)*o%gv(j)
            end do
         end associate
      end do
   end procedure observer_close
end submodule block
