!> The contact/impulse problem shared by every integrator with rigid contacts (docs/impulse.md):
!> the Delassus matrix, Newton's impact law as an LCP, the contact forces of persistent
!> contacts, the projection onto held contacts, and the accumulation (Zeno) policy.
!>
!> Conventions (Acary & Brogliato 2008, §3.1): contact k joins the sides a_k and b_k (node
!> indices, 0 for the ground or an immobile node); its gap rate is ġ_k = B_k v = v_b − v_a
!> (> 0 opening, = −δ̇ for the penetration δ = u_a − u_b − gap), and a compressive impulse
!> P_k ≥ 0 acts on the nodes as B_kᵀ P_k. With the columns C_k = A B_kᵀ of an inverse-mass
!> action A (M⁻¹ for the event-driven integrators, the inverse of Moreau–Jean's iteration
!> matrix Ŵ), the Delassus matrix is W = B A Bᵀ, W_kl = B_k C_l, symmetric positive
!> semi-definite, and an impulse changes the velocities by Δv = Σ_k P_k C_k, so ġ⁺ = ġ + W P.
!> Matrices are column-major; band storage as LAPACK's general band with kl = ku = kw:
!> W(i, j) lives in wb(kw + 1 + i − j, j).
module martello_impulse
   use martello_kinds, only: dp
   use martello_lcp, only: lcp_lemke, lcp_pgs, LCP_OK, LCP_RAY
   use martello_lapack, only: dpotrf, dpotrs
   implicit none
   private
   public :: contact_graph_t, contact_graph, delassus_columns, delassus_bandwidth, &
      delassus_diagonal_band, &
      newton_impulses, newton_impulses_band, contact_forces, apply_impulses, delassus_factor, &
      project_factored, impulse_accumulation, LEMKE_MAX, IMPULSE_OK, IMPULSE_INFEASIBLE, &
      IMPULSE_NOT_CONVERGED, IMPULSE_SINGULAR

   !> Up to this many contacts an LCP is solved by Lemke on a dense W (finite, exact to
   !> round-off, O(m³) at worst); beyond, by projected Gauss–Seidel with its direct finish on
   !> the band of W (O(m) a sweep on a chain).
   integer, parameter :: LEMKE_MAX = 64
   !> PGS: stop when a sweep changes no impulse by more than PGS_TOL·max impulse (the direct
   !> finish of martello_lcp then makes the solution exact to round-off)
   real(dp), parameter :: PGS_TOL = 1.0e-14_dp
   integer, parameter :: PGS_MAX_SWEEPS = 100000

   integer, parameter :: IMPULSE_OK = 0
   !> Lemke ended on a secondary ray: the LCP has no solution. For a positive semi-definite W
   !> this means redundant contacts that Newton's law cannot all satisfy (a node squeezed
   !> between two walls that it reaches at once).
   integer, parameter :: IMPULSE_INFEASIBLE = 1
   integer, parameter :: IMPULSE_NOT_CONVERGED = 2    !< pivot or sweep limit reached
   integer, parameter :: IMPULSE_SINGULAR = 3         !< W of the held set not positive definite

   !> Which contacts touch each node: con(ptr(i):ptr(i+1)−1). Built once a run; what makes the
   !> band Delassus matrix of a diagonal A cost O(m) instead of O(m²).
   type :: contact_graph_t
      integer, allocatable :: ptr(:), con(:)
   end type contact_graph_t

contains

   !> The node → contact adjacency of the contacts with use(k) true (sides 0 are left out).
   pure subroutine contact_graph(n, sa, sb, use, g)
      integer, intent(in) :: n, sa(:), sb(:)
      logical, intent(in) :: use(:)
      type(contact_graph_t), intent(out) :: g
      integer :: cnt(0:n), k
      cnt = 0
      do k = 1, size(sa)
         if (.not. use(k)) cycle
         cnt(sa(k)) = cnt(sa(k)) + 1
         cnt(sb(k)) = cnt(sb(k)) + 1
      end do
      allocate (g%ptr(n + 2), g%con(max(1, sum(cnt(1:n)))))
      g%ptr(1) = 1
      do k = 1, n
         g%ptr(k + 1) = g%ptr(k) + cnt(k)
      end do
      cnt = 0
      do k = 1, size(sa)
         if (.not. use(k)) cycle
         if (sa(k) > 0) then
            g%con(g%ptr(sa(k)) + cnt(sa(k))) = k; cnt(sa(k)) = cnt(sa(k)) + 1
         end if
         if (sb(k) > 0) then
            g%con(g%ptr(sb(k)) + cnt(sb(k))) = k; cnt(sb(k)) = cnt(sb(k)) + 1
         end if
      end do
   end subroutine contact_graph

   !> W_kl = B_k C_l for the contacts k, l = 1..m with sides sa, sb and columns c(:, l) =
   !> A B_lᵀ (any inverse-mass action: M⁻¹, consistent mass included, or Ŵ⁻¹).
   pure subroutine delassus_columns(sa, sb, c, w)
      integer, intent(in) :: sa(:), sb(:)
      real(dp), intent(in) :: c(:, :)
      real(dp), intent(out) :: w(:, :)
      integer :: k, l
      do l = 1, size(sa)
         do k = 1, size(sa)
            w(k, l) = side(c(:, l), sb(k)) - side(c(:, l), sa(k))
         end do
      end do
   end subroutine delassus_columns

   !> The bandwidth kw of W in the ordering act(1..m) of the contacts in an LCP (pos(c) = the
   !> position of contact c in act, 0 if absent): 1 for a chain of neighbours.
   pure integer function delassus_bandwidth(g, sa, sb, act, pos) result(kw)
      type(contact_graph_t), intent(in) :: g
      integer, intent(in) :: sa(:), sb(:), act(:), pos(:)
      integer :: i, k, side_, node, jj
      kw = 0
      do i = 1, size(act)
         k = act(i)
         do side_ = 1, 2
            node = merge(sa(k), sb(k), side_ == 1)
            if (node == 0) cycle
            do jj = g%ptr(node), g%ptr(node + 1) - 1
               if (pos(g%con(jj)) > 0) kw = max(kw, abs(pos(g%con(jj)) - i))
            end do
         end do
      end do
   end function delassus_bandwidth

   !> W in band storage (bandwidth kw from delassus_bandwidth; wb at least (2kw + 1, m)) for
   !> a diagonal A = diag(1/d) (Moreau–Jean's Ŵ of a lumped-mass chain without links): W_kl =
   !> Σ over the nodes i that contacts k and l share of s_k(i) s_l(i)/d_i (s = −1 on the a
   !> side, +1 on the b side): O(m) for a chain instead of the O(m²) of delassus_columns.
   pure subroutine delassus_diagonal_band(g, sa, sb, act, pos, d, kw, wb)
      type(contact_graph_t), intent(in) :: g
      integer, intent(in) :: sa(:), sb(:), act(:), pos(:), kw
      real(dp), intent(in) :: d(:)
      real(dp), intent(inout) :: wb(:, :)
      integer :: i, k, side_, node, jj, cj
      real(dp) :: si
      wb(:, 1:size(act)) = 0.0_dp
      do i = 1, size(act)
         k = act(i)
         do side_ = 1, 2
            node = merge(sa(k), sb(k), side_ == 1)
            if (node == 0) cycle
            si = merge(-1.0_dp, 1.0_dp, side_ == 1)
            do jj = g%ptr(node), g%ptr(node + 1) - 1
               cj = g%con(jj)
               if (pos(cj) == 0) cycle
               wb(kw + 1 + i - pos(cj), pos(cj)) = wb(kw + 1 + i - pos(cj), pos(cj)) + &
                  si*merge(-1.0_dp, 1.0_dp, sa(cj) == node)/d(node)
            end do
         end do
      end do
   end subroutine delassus_diagonal_band

   !> Newton's impact law at the velocity level (Moreau 1988; Pfeiffer & Glocker 1996, §6.2)
   !>
   !>    0 ≤ ġ⁺ + e ġ_ref  ⊥  P ≥ 0,   ġ⁺ = ġ_free + W P,
   !>
   !> as the LCP W P + q ≥ 0 ⊥ P ≥ 0, q = ġ_free + e ġ_ref. ġ_ref is the velocity the
   !> restitution acts on:
   !>  * an impact (event-driven integrators): ġ_free = ġ⁻ and ġ_ref = min(ġ⁻, 0), the
   !>    approach: a contact touching at rest or separating gets ġ⁺ ≥ 0 (it may not be pulled
   !>    closed, nor rebound);
   !>  * Moreau–Jean's discrete law (Acary & Brogliato 2008, eq. 10.12; Siconos' MoreauJeanOSI):
   !>    ġ_free the velocity of the step without impulses, ġ_ref = ġ_k at the step start, on
   !>    the contacts of its index set.
   !> On entry p is a warm start (used by PGS only).
   subroutine newton_impulses(w, g_free, g_ref, e, p, info, iterations)
      real(dp), intent(in) :: w(:, :), g_free(:), g_ref(:), e(:)
      real(dp), intent(inout) :: p(:)
      integer, intent(out) :: info, iterations
      call solve_dense(w, g_free + e*g_ref, p, info, iterations)
   end subroutine newton_impulses

   !> newton_impulses with W in band storage (bandwidth kw, m = size(g_free) columns).
   subroutine newton_impulses_band(wb, kw, g_free, g_ref, e, p, info, iterations)
      real(dp), intent(in) :: wb(:, :), g_free(:), g_ref(:), e(:)
      integer, intent(in) :: kw
      real(dp), intent(inout) :: p(:)
      integer, intent(out) :: info, iterations
      call solve_band(wb, kw, g_free + e*g_ref, p, info, iterations)
   end subroutine newton_impulses_band

   !> The contact forces λ of contacts at zero gap and zero gap rate (persistent contacts):
   !> Signorini's law at the acceleration level, 0 ≤ g̈ ⊥ λ ≥ 0 with g̈ = g̈_free + W λ
   !> (Pfeiffer & Glocker 1996, §5.3), the same LCP with q = g̈_free. The persistent-contact
   !> rule (docs/impulse.md §3): a contact stays held unless the solution opens it, λ = 0 with
   !> g̈ > 0; held contacts whose multiplier would turn tensile come out that way and are
   !> released, while a multiplier that only reaches 0 (nothing presses, nothing pulls: g̈ = 0)
   !> keeps the contact.
   subroutine contact_forces(w, a_free, lam, held, info, iterations)
      real(dp), intent(in) :: w(:, :), a_free(:)
      real(dp), intent(out) :: lam(:)
      logical, intent(out) :: held(:)
      integer, intent(out) :: info, iterations
      lam = 0.0_dp
      call solve_dense(w, a_free, lam, info, iterations)
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
   !> 2002 Thm 10.3, with a margin): the contacts are redundant, W only semi-definite.
   subroutine delassus_factor(w, info)
      real(dp), intent(inout) :: w(:, :)
      integer, intent(out) :: info
      real(dp) :: dmax
      integer :: j, m, lapack_info
      m = size(w, 1)
      info = IMPULSE_OK
      if (m == 0) return
      dmax = maxval([(abs(w(j, j)), j = 1, m)])
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
   subroutine project_factored(sa, sb, c, l, target, x, p)
      integer, intent(in) :: sa(:), sb(:)
      real(dp), intent(in) :: c(:, :), l(:, :), target(:)
      real(dp), intent(inout) :: x(:)
      real(dp), intent(out) :: p(:)
      integer :: k, m, info
      m = size(sa)
      do k = 1, m
         p(k) = target(k) - (side(x, sb(k)) - side(x, sa(k)))
      end do
      call dpotrs('L', m, 1, l, m, p, m, info)
      call apply_impulses(c, p, x)
   end subroutine project_factored

   !> The accumulation (Zeno) policy, the one rule of every integrator (docs/impulse.md §4).
   !>
   !> A contact leaving at time t with separation speed s ≥ 0 while its relative acceleration
   !> a > 0 presses it closed makes the flights τ, eτ, e²τ, … with τ = 2s/a (Newton's law
   !> shrinks each rebound by e; the bouncing ball of Moreau 1988, §9): a geometric series
   !> that ends at the accumulation point
   !>
   !>    t∞ = t + 2 s/(a (1 − e)),
   !>
   !> from which the contact is persistent (t_inf; huge when there is no accumulation).
   !> The integrator stops resolving the flights one by one — the sequence has accumulated —
   !> when
   !>  1. there is no rebound (s = 0 or e = 0): t∞ = t; whether the contact then stays closed
   !>     is the persistent-contact rule's decision (contact_forces), so a contact with no
   !>     rebound is a candidate whatever a;
   !>  2. or its next flight is below the integrator's resolution: shorter than tau_res (the
   !>     step h of a time-stepping scheme, which cannot hold two impacts in one step;
   !>     event_tol for the event-driven integrators, whose events closer than that are
   !>     simultaneous), or lower than height_res, s²/(2a) ≤ height_res (0 for time stepping;
   !>     the heights the event-driven integrators resolve, below which the gap never leaves
   !>     their position error and the next impact cannot be located).
   !> Deciding on t∞ itself (accumulated when t∞ falls inside the current interval) was
   !> measured and rejected, docs/impulse.md §4: with the step as interval Newmark–Lagrange
   !> chatters (flights shorter than a step whose tail outlasts it are held and released
   !> every step) and rk8pd resolves 8 of the first 10 impacts of P2 at e = 0.5; with event_tol
   !> as interval the flights fall below the rounding of the gap before t∞ comes within it.
   !> There is no accumulation without pressing (a ≤ 0: the contact flies off) or without
   !> dissipation (e ≥ 1: the flights do not shrink).
   pure subroutine impulse_accumulation(e, s, a, t, tau_res, height_res, accumulates, t_inf)
      real(dp), intent(in) :: e, s, a, t, tau_res, height_res
      logical, intent(out) :: accumulates
      real(dp), intent(out) :: t_inf
      accumulates = .true.
      t_inf = t
      if (s <= 0.0_dp .or. e <= 0.0_dp) return
      accumulates = .false.
      t_inf = huge(1.0_dp)
      if (.not. (a > 0.0_dp) .or. e >= 1.0_dp) return
      t_inf = t + 2.0_dp*s/(a*(1.0_dp - e))
      accumulates = 2.0_dp*s/a <= tau_res .or. s*s/(2.0_dp*a) <= height_res
   end subroutine impulse_accumulation

   ! ---- the LCP, dense or band -------------------------------------------------------------

   !> W z + q ≥ 0 ⊥ z ≥ 0 on a dense W: Lemke up to LEMKE_MAX contacts, PGS beyond (W copied
   !> into band storage of full width; z on entry is its warm start).
   subroutine solve_dense(w, q, z, info, iterations)
      real(dp), intent(in) :: w(:, :), q(:)
      real(dp), intent(inout) :: z(:)
      integer, intent(out) :: info, iterations
      real(dp), allocatable :: wb(:, :)
      integer :: m, i, j
      m = size(q)
      if (m <= LEMKE_MAX) then
         call lcp_lemke(w(1:m, 1:m), q, z, iterations, info)
      else
         allocate (wb(2*m - 1, m))
         do j = 1, m
            do i = 1, m
               wb(m + i - j, j) = w(i, j)
            end do
         end do
         call lcp_pgs(wb, m - 1, q, z, PGS_TOL, PGS_MAX_SWEEPS, iterations, info)
      end if
      info = status_of(info)
   end subroutine solve_dense

   !> W z + q ≥ 0 ⊥ z ≥ 0 on a band W (bandwidth kw): Lemke on its dense copy up to LEMKE_MAX
   !> contacts, PGS on the band beyond (z on entry: the warm start).
   subroutine solve_band(wb, kw, q, z, info, iterations)
      real(dp), intent(in) :: wb(:, :), q(:)
      integer, intent(in) :: kw
      real(dp), intent(inout) :: z(:)
      integer, intent(out) :: info, iterations
      real(dp), allocatable :: wd(:, :)
      integer :: m, i, j
      m = size(q)
      if (m <= LEMKE_MAX) then
         allocate (wd(m, m))
         wd = 0.0_dp
         do j = 1, m
            do i = max(1, j - kw), min(m, j + kw)
               wd(i, j) = wb(kw + 1 + i - j, j)
            end do
         end do
         call lcp_lemke(wd, q, z, iterations, info)
      else
         call lcp_pgs(wb(:, 1:m), kw, q, z, PGS_TOL, PGS_MAX_SWEEPS, iterations, info)
      end if
      info = status_of(info)
   end subroutine solve_band

   elemental integer function status_of(lcp_info)
      integer, intent(in) :: lcp_info
      status_of = IMPULSE_NOT_CONVERGED
      if (lcp_info == LCP_OK) status_of = IMPULSE_OK
      if (lcp_info == LCP_RAY) status_of = IMPULSE_INFEASIBLE
   end function status_of

   !> x at a contact side (0: the ground or an immobile node, which does not move).
   pure real(dp) function side(x, node)
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: node
      side = 0.0_dp
      if (node > 0) side = x(node)
   end function side
end module martello_impulse
