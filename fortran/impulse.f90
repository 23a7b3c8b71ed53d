!> The contact/impulse problem shared by every integrator with rigid contacts (docs/impulse.md):
!> the Delassus matrix, Newton's impact law and the contact forces of persistent contacts as
!> LCPs w = W z + q, 0 ≤ w ⊥ z ≥ 0, their solvers, the projection onto held contacts, and the
!> accumulation (Zeno) policy.
!>
!> Conventions (docs/impulse.md §1; Acary & Brogliato 2008, §3.1): contact k's row B_k
!> (martello_element_rows, rows b: the negative of its penetration row, so that for a node
!> pair B_k = e_b − e_a) gives its gap rate ġ_k = B_k v (> 0 opening: v_b − v_a for a pair,
!> the plan-point kinematics of two floors in general, docs/buildings.md); a compressive impulse
!> P_k ≥ 0 acts as B_kᵀ P_k. A term on an immobile node is harmless: the columns below vanish
!> there. With the columns
!> C_k = A B_kᵀ of an inverse-mass action A (M⁻¹, or Moreau–Jean's Ŵ⁻¹), W = B A Bᵀ, W_kl =
!> B_k C_l, and Δv = Σ_k P_k C_k. Matrices are column-major; band storage as LAPACK's general
!> band with kl = ku = kw: W(i, j) lives in wb(kw + 1 + i − j, j).
module martello_impulse
   use martello_kinds, only: dp
   use martello_lapack, only: dgbsv, dpotrf, dpotrs
   use martello_element_rows, only: rows_t, row_lo, row_hi
   implicit none
   private
   public :: contact_graph_t, contact_graph, delassus_columns, delassus_bandwidth, &
      delassus_diagonal_band, b_dot, newton_impulses, newton_impulses_band, kkt_bandwidth, contact_forces, &
      apply_impulses, delassus_factor, &
      project_factored, impulse_accumulation, flight_resolution, lcp_work_reals, LEMKE_MAX, IMPULSE_OK, &
      IMPULSE_INFEASIBLE, IMPULSE_NOT_CONVERGED, IMPULSE_SINGULAR, IMPULSE_NO_MEMORY

   !> Up to this many contacts an LCP is solved by Lemke on a dense W (finite, exact to
   !> round-off); beyond, by projected Gauss–Seidel with its direct finish on the band of W
   !> (O(m) a sweep on a chain). docs/impulse.md §2.
   integer, parameter :: LEMKE_MAX = 64
   !> PGS: stop when a sweep changes no impulse by more than PGS_TOL·max impulse (the direct
   !> finish makes the solution exact to round-off before that)
   real(dp), parameter :: PGS_TOL = 1.0e-14_dp
   integer, parameter :: PGS_MAX_SWEEPS = 100000
   !> newton_impulses_band: a sign is wrong when it is wrong by more than KKT_TOL of the
   !> scale of q or z (the band solve is exact to a few ulps of that scale)
   real(dp), parameter :: KKT_TOL = 1.0e-12_dp
   !> A flight of an impact sequence is resolved when the method locates its end to this
   !> fraction of its length (flight_resolution, docs/impulse.md §4)
   real(dp), parameter :: RESOLVED_FRACTION = 1.0e-2_dp

   integer, parameter :: IMPULSE_OK = 0
   !> no solution (Lemke's secondary ray): redundant contacts that Newton's law cannot all
   !> satisfy, e.g. a node that reaches two walls at once
   integer, parameter :: IMPULSE_INFEASIBLE = 1
   integer, parameter :: IMPULSE_NOT_CONVERGED = 2    !< pivot or sweep limit reached
   integer, parameter :: IMPULSE_SINGULAR = 3         !< W of the held set not positive definite
   !> the solver's work arrays (at most lcp_work_reals(m) reals) could not be allocated
   integer, parameter :: IMPULSE_NO_MEMORY = 4

   !> Which contacts touch each node: con(ptr(i):ptr(i+1)−1). Built once a run; it makes the
   !> band Delassus matrix of a diagonal A cost O(m) instead of O(m²).
   type :: contact_graph_t
      integer, allocatable :: ptr(:), con(:)
   end type contact_graph_t

contains
   !> The node → contact adjacency of the contacts with use(k) true (rows b).
   !> stat /= 0: g could not be allocated (n + 2 + the terms at most).
   pure subroutine contact_graph(n, b, use, g, stat)
      integer, intent(in) :: n
      type(rows_t), intent(in) :: b
      logical, intent(in) :: use(:)
      type(contact_graph_t), intent(out) :: g
      integer, intent(out) :: stat
      integer :: cnt(0:n), k, q, node
      cnt = 0
      do k = 1, size(use)
         if (.not. use(k)) cycle
         do q = row_lo(b, k), row_hi(b, k)
            cnt(b%node(q)) = cnt(b%node(q)) + 1
         end do
      end do
      allocate (g%ptr(n + 2), g%con(max(1, sum(cnt(1:n)))), stat=stat)
      if (stat /= 0) return
      g%ptr(1) = 1
      do k = 1, n
         g%ptr(k + 1) = g%ptr(k) + cnt(k)
      end do
      cnt = 0
      do k = 1, size(use)
         if (.not. use(k)) cycle
         do q = row_lo(b, k), row_hi(b, k)
            node = b%node(q)
            g%con(g%ptr(node) + cnt(node)) = k; cnt(node) = cnt(node) + 1
         end do
      end do
   end subroutine contact_graph

   !> B_k x over the nodes 1..n (x(:) indexed by node).
   pure real(dp) function b_dot(b, k, x) result(d)
      type(rows_t), intent(in) :: b
      integer, intent(in) :: k
      real(dp), intent(in) :: x(:)
      integer :: q
      d = 0.0_dp
      do q = row_lo(b, k), row_hi(b, k)
         d = d + b%coef(q)*x(b%node(q))
      end do
   end function b_dot

   !> W_kl = B_k C_l for the contacts list(k), list(l) of rows b and columns c(:, l) = A B_lᵀ
   !> (any inverse-mass action: M⁻¹, consistent mass included, or Ŵ⁻¹).
   pure subroutine delassus_columns(b, list, c, w)
      type(rows_t), intent(in) :: b
      integer, intent(in) :: list(:)
      real(dp), intent(in) :: c(:, :)
      real(dp), intent(out) :: w(:, :)
      integer :: k, l
      do l = 1, size(list)
         do k = 1, size(list)
            w(k, l) = b_dot(b, list(k), c(:, l))
         end do
      end do
   end subroutine delassus_columns

   !> The bandwidth kw of W in the ordering act(1..m) of the contacts in an LCP (pos(c) = the
   !> position of contact c in act, 0 if absent): 1 for a chain of neighbours.
   pure integer function delassus_bandwidth(g, b, act, pos) result(kw)
      type(contact_graph_t), intent(in) :: g
      type(rows_t), intent(in) :: b
      integer, intent(in) :: act(:), pos(:)
      integer :: i, k, q, node, jj
      kw = 0
      do i = 1, size(act)
         k = act(i)
         do q = row_lo(b, k), row_hi(b, k)
            node = b%node(q)
            do jj = g%ptr(node), g%ptr(node + 1) - 1
               if (pos(g%con(jj)) > 0) kw = max(kw, abs(pos(g%con(jj)) - i))
            end do
         end do
      end do
   end function delassus_bandwidth

   !> W in band storage (bandwidth kw from delassus_bandwidth; wb at least (2kw + 1, m)) for
   !> a diagonal A = diag(1/d) (Moreau–Jean's Ŵ of a lumped-mass chain without links): W_kl =
   !> Σ over the nodes i that contacts k and l share of b_k(i) b_l(i)/d_i: O(m) for a chain
   !> instead of the O(m²) of delassus_columns.
   pure subroutine delassus_diagonal_band(g, b, act, pos, d, kw, wb)
      type(contact_graph_t), intent(in) :: g
      type(rows_t), intent(in) :: b
      integer, intent(in) :: act(:), pos(:), kw
      real(dp), intent(in) :: d(:)
      real(dp), intent(inout) :: wb(:, :)
      integer :: i, k, q, r, node, jj, cj
      wb(:, 1:size(act)) = 0.0_dp
      do i = 1, size(act)
         k = act(i)
         do q = row_lo(b, k), row_hi(b, k)
            node = b%node(q)
            do jj = g%ptr(node), g%ptr(node + 1) - 1
               cj = g%con(jj)
               if (pos(cj) == 0) cycle
               do r = row_lo(b, cj), row_hi(b, cj)      ! the other contact's term at this node
                  if (b%node(r) /= node) cycle
                  wb(kw + 1 + i - pos(cj), pos(cj)) = wb(kw + 1 + i - pos(cj), pos(cj)) + &
                     b%coef(q)*b%coef(r)/d(node)
               end do
            end do
         end do
      end do
   end subroutine delassus_diagonal_band

   !> Newton's impact law at the velocity level (docs/impulse.md §2; Moreau 1988; Pfeiffer &
   !> Glocker 1996, §6.2), 0 ≤ ġ⁺ + e ġ_ref ⊥ P ≥ 0 with ġ⁺ = ġ_free + W P: the LCP with
   !> q = ġ_free + e ġ_ref. ġ_ref is what the restitution acts on: the approach min(ġ⁻, 0) of
   !> an impact (ġ_free = ġ⁻), or Moreau–Jean's start-of-step ġ_k (Acary & Brogliato 2008,
   !> eq. 10.12). W dense (w) or in band storage (wb, kw); p on entry: PGS's warm start.
   subroutine newton_impulses(g_free, g_ref, e, p, info, iterations, w, wb, kw)
      real(dp), intent(in) :: g_free(:), g_ref(:), e(:)
      real(dp), intent(inout) :: p(:)
      integer, intent(out) :: info, iterations
      real(dp), intent(in), optional :: w(:, :), wb(:, :)
      integer, intent(in), optional :: kw
      call solve_lcp(g_free + e*g_ref, p, info, iterations, w, wb, kw)
   end subroutine newton_impulses

   !> The half-bandwidth of the saddle-point matrix of newton_impulses_band, [[Ŵ, −Bᵀ], [B, 0]]
   !> on the contacts act of rows b, for a band Ŵ of n nodes and half-bandwidth kd: each
   !> multiplier is ordered right after the last node of its row (kkt_order). 2 for a chain of
   !> neighbours; the band solve costs O((n + m) kk²).
   pure integer function kkt_bandwidth(b, act, n, kd) result(kk)
      type(rows_t), intent(in) :: b
      integer, intent(in) :: act(:), n, kd
      integer :: pv(n), pz(size(act)), i, j, q
      call kkt_order(b, act, n, pv, pz)
      kk = 0
      do i = 1, n - kd
         kk = max(kk, pv(i + kd) - pv(i))
      end do
      do j = 1, size(act)
         do q = row_lo(b, act(j)), row_hi(b, act(j))
            kk = max(kk, pz(j) - pv(b%node(q)))
         end do
      end do
   end function kkt_bandwidth

   !> The unknowns of the saddle-point system in the order v_1, the multipliers of the rows
   !> whose last node is 1, v_2, …: pv(i) the position of node i, pz(j) that of contact act(j).
   pure subroutine kkt_order(b, act, n, pv, pz)
      type(rows_t), intent(in) :: b
      integer, intent(in) :: act(:), n
      integer, intent(out) :: pv(n), pz(:)
      integer :: cnt(0:n), last(size(act)), i, j, at
      cnt = 0
      do j = 1, size(act)
         last(j) = max(0, maxval(b%node(row_lo(b, act(j)):row_hi(b, act(j)))))
         cnt(last(j)) = cnt(last(j)) + 1
      end do
      at = cnt(0)                     ! rows on no free node first (singular: never in act)
      cnt(0) = 0
      do i = 1, n
         at = at + 1
         pv(i) = at
         at = at + cnt(i)
         cnt(i) = pv(i)               ! the next multiplier after node i goes to cnt(i) + 1
      end do
      do j = 1, size(act)
         cnt(last(j)) = cnt(last(j)) + 1
         pz(j) = cnt(last(j))
      end do
   end subroutine kkt_order

   !> Newton's law (as newton_impulses) on the contacts act(1..m) of rows b when the inverse-mass
   !> action is A = Ŵ⁻¹ of a band matrix Ŵ (Moreau–Jean with links or a consistent mass):
   !> W = B Ŵ⁻¹ Bᵀ is then dense and is never formed. Block principal pivoting (Júdice & Pires
   !> 1994) on the saddle-point form of W_JJ z_J = −q_J,
   !>
   !>    [ Ŵ     −s B_Jᵀ ] [ Δv ]   [   0    ]
   !>    [ s B_J    0    ] [ z/s] = [ −s q_J ],   w = q + B Δv,
   !>
   !> a band solve of half-bandwidth kkt_bandwidth (2 on a chain: O(n + m) a round instead of
   !> the O(n m) columns, O(m²) matrix and O(m³) finish of the dense W); s scales each row to Ŵ's
   !> diagonal on its nodes. J starts from the support of p (the warm start) and the contacts
   !> not separating (q ≤ KKT_TOL·max|q|); a round flips every wrong sign (z_j < 0 on J, w_j < 0 off it) while their number falls,
   !> else, after three rounds without progress, only the wrong sign of the least index
   !> (Murty's rule: finite for the P-matrix of independent contacts). Accepted when no sign is
   !> wrong by more than KKT_TOL of the scale of q or z; impulses within KKT_TOL of that scale
   !> are set to zero (round-off, not impacts). wab: Ŵ in LAPACK band storage with
   !> A(i, j) at wab(size(wab, 1) − kd + i − j, j) (kd + 1 + i − j in 2kd + 1 rows, or dgbtrf's
   !> 3kd + 1). info: IMPULSE_SINGULAR when the saddle-point matrix is (dependent contacts),
   !> IMPULSE_NOT_CONVERGED after 3m + 20 rounds, IMPULSE_NO_MEMORY; p unchanged then (the
   !> caller falls back to the dense W).
   subroutine newton_impulses_band(wab, kd, b, act, g_free, g_ref, e, p, info, rounds)
      real(dp), intent(in) :: wab(:, :)
      integer, intent(in) :: kd
      type(rows_t), intent(in) :: b
      integer, intent(in) :: act(:)
      real(dp), intent(in) :: g_free(:), g_ref(:), e(:)
      real(dp), intent(inout) :: p(:)
      integer, intent(out) :: info, rounds
      real(dp), allocatable :: ab(:, :), x(:)
      integer, allocatable :: ipiv(:), pv(:), pz(:)
      real(dp) :: q(size(act)), s(size(act)), z(size(act)), w, qscale, zscale
      logical :: inj(size(act)), wrong(size(act))
      integer :: n, m, nn, kk, ld, dg, i, j, c, r, st, nwrong, best, stalled
      n = size(wab, 2); m = size(act); dg = size(wab, 1) - kd
      rounds = 0
      info = IMPULSE_OK
      if (m == 0) return
      q = g_free + e*g_ref
      kk = kkt_bandwidth(b, act, n, kd)
      nn = n + m; ld = 3*kk + 1
      info = IMPULSE_NO_MEMORY
      allocate (ab(ld, nn), x(nn), ipiv(nn), pv(n), pz(m), stat=st)
      if (st /= 0) return
      info = IMPULSE_OK
      call kkt_order(b, act, n, pv, pz)
      do j = 1, m
         c = act(j)
         s(j) = 0.0_dp
         do r = row_lo(b, c), row_hi(b, c)
            s(j) = max(s(j), abs(wab(dg, b%node(r))))
         end do
         s(j) = max(s(j), tiny(1.0_dp))
      end do
      qscale = maxval(abs(q))
      ! the warm start and every contact not separating: a contact at rest in a touching row
      ! (Newton's cradle) is in J from the first round, not one neighbour a round
      inj = p > 0.0_dp .or. q <= KKT_TOL*qscale
      best = m + 1; stalled = 0
      do rounds = 1, 3*m + 20
         ! the saddle-point band in dgbsv's storage: entry (r, col) at ab(2kk + 1 + r − col, col)
         ab = 0.0_dp; x = 0.0_dp
         do j = 1, n
            do i = max(1, j - kd), min(n, j + kd)
               ab(2*kk + 1 + pv(i) - pv(j), pv(j)) = wab(dg + i - j, j)
            end do
         end do
         do j = 1, m
            c = act(j)
            if (.not. inj(j)) then
               ab(2*kk + 1, pz(j)) = 1.0_dp
               cycle
            end if
            do r = row_lo(b, c), row_hi(b, c)
               i = pv(b%node(r))
               ab(2*kk + 1 + i - pz(j), pz(j)) = -s(j)*b%coef(r)
               ab(2*kk + 1 + pz(j) - i, i) = s(j)*b%coef(r)
            end do
            x(pz(j)) = -s(j)*q(j)
         end do
         call dgbsv(nn, kk, kk, 1, ab, ld, ipiv, x, nn, st)
         if (st /= 0) then
            info = IMPULSE_SINGULAR; return
         end if
         ! z on J, w = q + B Δv off J; the wrong signs
         z = 0.0_dp
         do j = 1, m
            if (inj(j)) z(j) = s(j)*x(pz(j))
         end do
         zscale = max(maxval(abs(z)), tiny(1.0_dp))
         do j = 1, m
            if (inj(j)) then
               wrong(j) = z(j) < -KKT_TOL*zscale
            else
               c = act(j)
               w = q(j)
               do r = row_lo(b, c), row_hi(b, c)
                  w = w + b%coef(r)*x(pv(b%node(r)))
               end do
               wrong(j) = w < -KKT_TOL*qscale
            end if
         end do
         nwrong = count(wrong)
         if (nwrong == 0) then
            ! an impulse within the solution's round-off is none (no impact of 1e-18 N s)
            p = merge(z, 0.0_dp, z > KKT_TOL*zscale)
            return
         end if
         if (nwrong < best) then
            best = nwrong; stalled = 0
         else
            stalled = stalled + 1
         end if
         if (stalled < 3) then
            where (wrong) inj = .not. inj
         else
            j = findloc(wrong, .true., dim=1)
            inj(j) = .not. inj(j)
         end if
      end do
      rounds = 3*m + 20
      info = IMPULSE_NOT_CONVERGED
   end subroutine newton_impulses_band

   !> The contact forces λ of contacts at zero gap and zero gap rate: Signorini's law at the
   !> acceleration level, 0 ≤ g̈ ⊥ λ ≥ 0 with g̈ = g̈_free + W λ (Pfeiffer & Glocker 1996, §5.3).
   !> The persistent-contact rule (docs/impulse.md §3): held = the solution does not open the
   !> contact (λ > 0, or g̈ ≤ 0); a multiplier that would turn tensile opens it, one that only
   !> reaches 0 with nothing pulling (g̈ = 0) does not.
   subroutine contact_forces(w, a_free, lam, held, info, iterations)
      real(dp), intent(in) :: w(:, :), a_free(:)
      real(dp), intent(out) :: lam(:)
      logical, intent(out) :: held(:)
      integer, intent(out) :: info, iterations
      lam = 0.0_dp
      call solve_lcp(a_free, lam, info, iterations, w=w)
      held = lam > 0.0_dp .or. .not. (matmul(w, lam) + a_free > 0.0_dp)
   end subroutine contact_forces

   !> x ← x + Σ_k p_k c(:, k): the velocity jump of impulses p (or the displacement of a
   !> projection), through the columns c(:, k) = A B_kᵀ.
   pure subroutine apply_impulses(c, p, x)
      real(dp), intent(in) :: c(:, :), p(:)
      real(dp), intent(inout) :: x(:)
      integer :: k
      do k = 1, size(p)
         if (p(k) /= 0.0_dp) x = x + p(k)*c(:, k)
      end do
   end subroutine apply_impulses

   !> Cholesky factorisation in place (LAPACK dpotrf, L in the lower triangle) of the Delassus
   !> matrix of contacts held together. IMPULSE_SINGULAR when a pivot falls to the rounding of
   !> the largest diagonal, L_jj² ≤ 64 ε m max W_ii (the Cholesky backward error bound, Higham
   !> 2002 Thm 10.3, with a margin): the contacts are redundant, W only semi-definite. One
   !> contact keeps W itself: its solve is then one division, exact to one rounding.
   subroutine delassus_factor(w, info)
      real(dp), intent(inout) :: w(:, :)
      integer, intent(out) :: info
      real(dp) :: dmax
      integer :: j, m, lapack_info
      m = size(w, 1)
      info = IMPULSE_OK
      if (m == 0) return
      dmax = maxval([(abs(w(j, j)), j = 1, m)])
      if (m == 1) then
         if (.not. (w(1, 1) > 0.0_dp)) info = IMPULSE_SINGULAR
         return
      end if
      call dpotrf('L', m, w, m, lapack_info)
      if (lapack_info /= 0) then
         info = IMPULSE_SINGULAR
      else if (.not. all([(w(j, j)**2 > 64.0_dp*epsilon(1.0_dp)*m*dmax, j = 1, m)])) then
         info = IMPULSE_SINGULAR
      end if
   end subroutine delassus_factor

   !> The mass-weighted projection of x onto B x = target for contacts held together
   !> (Acary & Brogliato 2008, §4.2: the closest point in the metric A⁻¹): with W factored
   !> by delassus_factor, P = W⁻¹ (target − B x) and x ← x + Σ P_k c(:, k). On the velocities
   !> with target 0 it is the plastic impulse of the held set; on the accelerations, the
   !> bilateral contact forces; on the displacements with target −gap, the return onto δ = 0.
   subroutine project_factored(b, list, c, l, target, x, p)
      type(rows_t), intent(in) :: b
      integer, intent(in) :: list(:)
      real(dp), intent(in) :: c(:, :), l(:, :), target(:)
      real(dp), intent(inout) :: x(:)
      real(dp), intent(out) :: p(:)
      integer :: k, m, info
      m = size(list)
      do k = 1, m
         p(k) = target(k) - b_dot(b, list(k), x)
      end do
      if (m == 1) then
         p(1) = p(1)/l(1, 1)
      else
         call dpotrs('L', m, 1, l, m, p, m, info)
      end if
      call apply_impulses(c, p, x)
   end subroutine project_factored

   !> The accumulation (Zeno) rule, the one rule of every integrator (docs/impulse.md §4),
   !> decided from the impact sequence and the method's resolution, never from output
   !> settings. A contact leaving at t with separation speed s ≥ 0, pressed by its relative
   !> acceleration a > 0, makes the flights τ, eτ, e²τ, … (τ = 2s/a; Moreau 1988, §9) that
   !> end at the accumulation point t∞ = t + 2s/(a(1 − e)), returned in t_inf (huge when there
   !> is none): the contact is persistent from there. It has accumulated
   !>  1. with no rebound (s = 0 or e = 0): t∞ = t, the persistent-contact rule decides;
   !>  2. when its next flight, the longest of the remaining ones, is one the method does not
   !>     resolve, τ ≤ flight_resolution(…), and the constant-acceleration series predicts the
   !>     end of the rest as well as a resolved flight's: a changes over the next flight by
   !>     da, so the rest, T = τ/(1 − e) long, ends off by about |da/τ| T²/a, at most
   !>     RESOLVED_FRACTION τ when |da| ≤ RESOLVED_FRACTION (1 − e)² a.
   !> No accumulation without pressing (a ≤ 0) or dissipation (e ≥ 1).
   pure subroutine impulse_accumulation(e, s, a, da, t, t_res, d_res, v_res, restarts, &
                                        accumulates, t_inf)
      real(dp), intent(in) :: e, s, a, da, t, t_res, d_res, v_res
      logical, intent(in) :: restarts
      logical, intent(out) :: accumulates
      real(dp), intent(out) :: t_inf
      real(dp) :: tau
      accumulates = .true.
      t_inf = t
      if (s <= 0.0_dp .or. e <= 0.0_dp) return
      accumulates = .false.
      t_inf = huge(1.0_dp)
      if (.not. (a > 0.0_dp) .or. e >= 1.0_dp) return
      tau = 2.0_dp*s/a
      t_inf = t + tau/(1.0_dp - e)
      accumulates = tau <= flight_resolution(a, t_res, d_res, v_res, restarts) .and. &
                    abs(da) <= RESOLVED_FRACTION*(1.0_dp - e)**2*a
   end subroutine impulse_accumulation

   !> The shortest flight a method resolves under the pressing acceleration a > 0
   !> (docs/impulse.md §4): one whose end it locates to RESOLVED_FRACTION (1 %) of its length,
   !> and no shorter than t_res (the step of a time-stepping scheme; event_tol of an
   !> event-driven one: closer events are simultaneous). A flight τ leaves at aτ/2: its end is
   !> off by d/(aτ/2) in time when its gap is off by d, and its length by 2v/a when its launch
   !> speed is off by v. d is the method's position error over the flight: d_res, its error a
   !> step, for a one-step method; for a multistep one that restarts at order 1 after every
   !> impact (restarts: BDF) it adds up over the flight's steps, h₁ = √(2 d_res/a) long
   !> (backward Euler's error a h²/2 is d_res), to τ √(a d_res/2), and its end is off by h₁.
   pure real(dp) function flight_resolution(a, t_res, d_res, v_res, restarts)
      real(dp), intent(in) :: a, t_res, d_res, v_res
      logical, intent(in) :: restarts
      real(dp) :: d
      d = max(d_res, 0.0_dp)
      if (restarts) then
         flight_resolution = sqrt(2.0_dp*d/a)/RESOLVED_FRACTION
      else
         flight_resolution = sqrt(2.0_dp*d/(RESOLVED_FRACTION*a))
      end if
      flight_resolution = max(t_res, flight_resolution, 2.0_dp*max(v_res, 0.0_dp)/(RESOLVED_FRACTION*a))
   end function flight_resolution

   ! ---- the LCP solvers (docs/impulse.md §2) -----------------------------------------------

   !> The most reals solve_lcp holds at once for m contacts (a dense W copied into a band of
   !> 2m − 1 rows, and the polish's band of 3m − 2): what an IMPULSE_NO_MEMORY failure could
   !> not get, at most.
   pure real(dp) function lcp_work_reals(m)
      integer, intent(in) :: m
      lcp_work_reals = 5.0_dp*real(m, dp)**2
   end function lcp_work_reals

   !> W z + q ≥ 0 ⊥ z ≥ 0 with W dense (w) or in band storage (wb, kw): Lemke on the dense W up
   !> to LEMKE_MAX contacts, PGS on the band beyond (a dense W is copied into a band of full
   !> width, a band W into a dense one for Lemke); z on entry is PGS's warm start.
   subroutine solve_lcp(q, z, info, iterations, w, wb, kw)
      real(dp), intent(in) :: q(:)
      real(dp), intent(inout) :: z(:)
      integer, intent(out) :: info, iterations
      real(dp), intent(in), optional :: w(:, :), wb(:, :)
      integer, intent(in), optional :: kw
      real(dp), allocatable :: wd(:, :), wbd(:, :)
      integer :: m, i, j, st
      m = size(q)
      info = IMPULSE_NO_MEMORY; iterations = 0
      if (present(w)) then
         if (m <= LEMKE_MAX) then
            call lemke(w(1:m, 1:m), q, z, iterations, info)
            return
         end if
         allocate (wbd(2*m - 1, m), stat=st)
         if (st /= 0) return
         forall (i = 1:m, j = 1:m) wbd(m + i - j, j) = w(i, j)
         call pgs(wbd, m - 1, q, z, PGS_TOL, PGS_MAX_SWEEPS, iterations, info)
      else if (m <= LEMKE_MAX) then
         allocate (wd(m, m), stat=st)
         if (st /= 0) return
         wd = 0.0_dp
         forall (j = 1:m, i = 1:m, abs(i - j) <= kw) wd(i, j) = wb(kw + 1 + i - j, j)
         call lemke(wd, q, z, iterations, info)
      else
         call pgs(wb(:, 1:m), kw, q, z, PGS_TOL, PGS_MAX_SWEEPS, iterations, info)
      end if
   end subroutine solve_lcp

   !> Lemke's method with the covering vector (1, …, 1). On return z solves the LCP and
   !> pivots is the number of pivots made (0 when q ≥ 0, z = 0). The ratio test breaks ties
   !> in favour of the artificial variable z0 (it ends the algorithm), then of the smallest
   !> row. info = IMPULSE_INFEASIBLE when the entering column has no positive entry (W not copositive-
   !> plus on a feasible problem: impossible for a positive semi-definite Delassus operator
   !> with a feasible LCP); IMPULSE_NOT_CONVERGED after max_pivots.
   pure subroutine lemke(w, q, z, pivots, info, max_pivots)
      real(dp), intent(in) :: w(:, :), q(:)
      real(dp), intent(out) :: z(:)
      integer, intent(out) :: pivots, info
      integer, intent(in), optional :: max_pivots
      ! tableau: binv(n, n) = B⁻¹, x(n) = B⁻¹ q; basis(i) = variable basic in row i:
      ! 1..n are w, n+1..2n are z, 2n+1 is z0
      real(dp) :: binv(size(q), size(q)), x(size(q)), col(size(q)), piv_tol, ratio, best
      integer :: basis(size(q)), n, r, i, entering, leaving, maxp
      logical :: solved
      n = size(q)
      z = 0.0_dp
      pivots = 0
      info = IMPULSE_OK
      if (n == 0) return
      if (minval(q) >= 0.0_dp) return
      maxp = 50*n + 10
      if (present(max_pivots)) maxp = max_pivots
      binv = 0.0_dp
      do i = 1, n
         binv(i, i) = 1.0_dp
         basis(i) = i
      end do
      x = q
      ! z0 enters; the most negative q leaves
      r = minloc(q, 1)
      col = -1.0_dp
      call lemke_pivot(binv, x, r, col, pivots)
      leaving = basis(r)
      basis(r) = 2*n + 1
      entering = complement(leaving)
      solved = .false.
      do while (pivots < maxp)
         ! column of the entering variable in the current basis: B⁻¹ A_j
         if (entering <= n) then
            col = binv(:, entering)                       ! A_j = e_j
         else
            col = -matmul(binv, w(:, entering - n))       ! A_j = −W(:, j)
         end if
         piv_tol = 1.0e3_dp*epsilon(1.0_dp)*max(maxval(abs(col)), tiny(1.0_dp))
         r = 0
         best = huge(1.0_dp)
         do i = 1, n
            if (col(i) > piv_tol) then
               ratio = max(x(i), 0.0_dp)/col(i)
               if (ratio < best .or. (ratio == best .and. basis(i) == 2*n + 1)) then
                  best = ratio; r = i
               end if
            end if
         end do
         if (r == 0) then
            info = IMPULSE_INFEASIBLE
            exit
         end if
         call lemke_pivot(binv, x, r, col, pivots)
         leaving = basis(r)
         basis(r) = entering
         if (leaving == 2*n + 1) then                     ! z0 left the basis: solved
            solved = .true.
            exit
         end if
         entering = complement(leaving)
      end do
      if (.not. solved .and. info == IMPULSE_OK) info = IMPULSE_NOT_CONVERGED
      do i = 1, n
         if (basis(i) > n .and. basis(i) <= 2*n) z(basis(i) - n) = max(x(i), 0.0_dp)
      end do
   contains
      pure integer function complement(var)
         integer, intent(in) :: var
         if (var <= n) then
            complement = var + n
         else
            complement = var - n
         end if
      end function complement

   end subroutine lemke

   !> Gauss–Jordan pivot of Lemke's tableau (B⁻¹ and x = B⁻¹q) on row rr, column cc = B⁻¹A_j.
   pure subroutine lemke_pivot(binv, x, rr, cc, pivots)
      real(dp), intent(inout) :: binv(:, :), x(:)
      integer, intent(in) :: rr
      real(dp), intent(in) :: cc(:)
      integer, intent(inout) :: pivots
      integer :: k
      real(dp) :: p
      p = cc(rr)
      binv(rr, :) = binv(rr, :)/p
      x(rr) = x(rr)/p
      do k = 1, size(x)
         if (k == rr .or. cc(k) == 0.0_dp) cycle
         binv(k, :) = binv(k, :) - cc(k)*binv(rr, :)
         x(k) = x(k) - cc(k)*x(rr)
      end do
      pivots = pivots + 1
   end subroutine lemke_pivot

   !> Projected Gauss–Seidel, z_i ← max(0, z_i − (q + W z)_i / W_ii) for i = 1..n, from the
   !> given z (a warm start), with an exact finish: after 8 sweeps, every POLISH_EVERY, and once the
   !> sweeps change z by less than √tol, the support J = {z_i > 0} is taken as the active set
   !> and W_JJ z_J = −q_J solved directly (a band solve: W_JJ keeps W's bandwidth). If that z
   !> is feasible (z_J ≥ 0, (Wz + q)_i ≥ −tol·scale off J) it is the solution to round-off;
   !> plain PGS converges only linearly, at a rate 1 − O(1/n²) on a chain of n contacts
   !> pressed together (Newton's cradle), so without the finish it would stop far from it.
   !> Otherwise PGS stops when a sweep changes no z_i by more than tol·max z.
   !> Rows with W_ii ≤ 0 (a contact between immobile sides) are left at z_i = 0.
   subroutine pgs(wb, kw, q, z, tol, max_sweeps, sweeps, info)
      real(dp), intent(in) :: wb(:, :)    !< (2kw + 1, n) band
      integer, intent(in) :: kw
      real(dp), intent(in) :: q(:), tol
      real(dp), intent(inout) :: z(:)
      integer, intent(in) :: max_sweeps
      integer, intent(out) :: sweeps, info
      integer, parameter :: POLISH_EVERY = 64
      integer :: i, j, n
      real(dp) :: s, znew, change, zmax
      logical :: done
      n = size(q)
      info = IMPULSE_OK
      sweeps = 0
      if (n == 0) return
      z = max(z, 0.0_dp)
      do sweeps = 1, max_sweeps
         change = 0.0_dp; zmax = 0.0_dp
         do i = 1, n
            if (wb(kw + 1, i) <= 0.0_dp) then
               z(i) = 0.0_dp; cycle
            end if
            s = q(i)
            do j = max(1, i - kw), min(n, i + kw)
               s = s + wb(kw + 1 + i - j, j)*z(j)
            end do
            znew = max(0.0_dp, z(i) - s/wb(kw + 1, i))
            change = max(change, abs(znew - z(i)))
            z(i) = znew
            zmax = max(zmax, znew)
         end do
         if (change <= tol*max(zmax, tiny(1.0_dp))) return
         if (sweeps == 8 .or. mod(sweeps, POLISH_EVERY) == 0 .or. change <= sqrt(tol)*zmax) then
            call polish(wb, kw, q, z, tol, done, info)
            if (done .or. info /= IMPULSE_OK) return
         end if
      end do
      sweeps = max_sweeps
      info = IMPULSE_NOT_CONVERGED
   end subroutine pgs

   !> Block principal pivoting from the support of z (Júdice & Pires 1994, without their
   !> safeguard): solve W_JJ z_J = −q_J (dgbsv on the compressed band), drop from J the
   !> indices with z_j < 0, add those off J with (Wz + q)_i < 0, repeat. Accepted when both
   !> sets are empty within tol (z is then the LCP solution to round-off); after MAX_ROUNDS
   !> rounds z is left unchanged and PGS carries on.
   subroutine polish(wb, kw, q, z, tol, done, stat)
      real(dp), intent(in) :: wb(:, :), q(:), tol
      integer, intent(in) :: kw
      real(dp), intent(inout) :: z(:)
      logical, intent(out) :: done
      integer, intent(out) :: stat    !< IMPULSE_NO_MEMORY: its band could not be allocated
      integer, parameter :: MAX_ROUNDS = 8
      integer :: idx(size(q)), ipiv(size(q)), nj, i, j, k, l, n, info, round
      logical :: inj(size(q)), changed
      real(dp), allocatable :: ab(:, :)
      real(dp) :: zj(size(q)), zfull(size(q)), w, qscale, zscale
      n = size(q)
      done = .false.
      inj = z > 0.0_dp
      qscale = maxval(abs(q))
      stat = IMPULSE_NO_MEMORY
      allocate (ab(3*kw + 1, n), stat=info)
      if (info /= 0) return
      stat = IMPULSE_OK
      do round = 1, MAX_ROUNDS
         nj = 0
         do i = 1, n
            if (inj(i)) then
               nj = nj + 1; idx(nj) = i
            end if
         end do
         zfull = 0.0_dp
         if (nj > 0) then
            ! compressed band of W_JJ: J's rows and columns k, l with |idx(k) − idx(l)| ≤ kw
            ab(:, 1:nj) = 0.0_dp
            do l = 1, nj
               do k = max(1, l - kw), min(nj, l + kw)
                  if (abs(idx(k) - idx(l)) <= kw) &
                     ab(2*kw + 1 + k - l, l) = wb(kw + 1 + idx(k) - idx(l), idx(l))
               end do
               zj(l) = -q(idx(l))
            end do
            call dgbsv(nj, kw, kw, 1, ab, 3*kw + 1, ipiv, zj, nj, info)
            if (info /= 0) return
            zfull(idx(1:nj)) = zj(1:nj)
         end if
         zscale = max(maxval(abs(zfull)), tiny(1.0_dp))
         changed = .false.
         do i = 1, n
            if (inj(i)) then
               if (zfull(i) < -tol*zscale) then
                  inj(i) = .false.; changed = .true.
               end if
            else
               w = q(i)
               do j = max(1, i - kw), min(n, i + kw)
                  w = w + wb(kw + 1 + i - j, j)*zfull(j)
               end do
               if (w < -tol*qscale) then
                  inj(i) = .true.; changed = .true.
               end if
            end if
         end do
         if (.not. changed) then
            z = max(zfull, 0.0_dp)
            done = .true.
            return
         end if
      end do
   end subroutine polish

end module martello_impulse
