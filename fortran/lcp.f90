!> Linear complementarity problems w = W z + q, 0 ≤ w ⊥ z ≥ 0, for the impulses of
!> Moreau–Jean time stepping (W = the Delassus operator B Ŵ⁻¹ Bᵀ, symmetric positive
!> semi-definite; z = the contact impulses).
!>  - lcp_lemke: Lemke's complementary pivoting (Lemke 1965; Cottle, Pang & Stone 1992,
!>    §4.4) on a dense tableau. Finite, exact up to round-off; O(n²) a pivot, at most a few n
!>    pivots for the P-matrices of independent contacts. For a few dozen active contacts.
!>  - lcp_pgs: projected Gauss–Seidel on W held in band storage, finished by a direct band
!>    solve on the support it identifies. A chain whose structural matrix Ŵ is diagonal
!>    (masses on springs to ground, contacts between neighbours) has a tridiagonal W
!>    (kw = 1), so a sweep and the finish cost O(n) instead of O(n²) and O(n³).
!> Matrices are column-major; band storage as LAPACK's general band with kl = ku = kw:
!> W(i, j) lives in wb(kw + 1 + i − j, j).
module martello_lcp
   use martello_kinds, only: dp
   use martello_lapack, only: dgbsv
   implicit none
   private
   public :: lcp_lemke, lcp_pgs, LCP_OK, LCP_RAY, LCP_MAX_ITER

   integer, parameter :: LCP_OK = 0
   integer, parameter :: LCP_RAY = 1          !< Lemke ended on a secondary ray: no solution found
   integer, parameter :: LCP_MAX_ITER = 2     !< iteration limit reached


contains

   !> Lemke's method with the covering vector (1, …, 1). On return z solves the LCP and
   !> pivots is the number of pivots made (0 when q ≥ 0, z = 0). The ratio test breaks ties
   !> in favour of the artificial variable z0 (it ends the algorithm), then of the smallest
   !> row. info = LCP_RAY when the entering column has no positive entry (W not copositive-
   !> plus on a feasible problem: impossible for a positive semi-definite Delassus operator
   !> with a feasible LCP); LCP_MAX_ITER after max_pivots.
   pure subroutine lcp_lemke(w, q, z, pivots, info, max_pivots)
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
      info = LCP_OK
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
            info = LCP_RAY
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
      if (.not. solved .and. info == LCP_OK) info = LCP_MAX_ITER
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

   end subroutine lcp_lemke

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
   subroutine lcp_pgs(wb, kw, q, z, tol, max_sweeps, sweeps, info)
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
      info = LCP_OK
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
            call polish(wb, kw, q, z, tol, done)
            if (done) return
         end if
      end do
      sweeps = max_sweeps
      info = LCP_MAX_ITER
   end subroutine lcp_pgs

   !> Block principal pivoting from the support of z (Júdice & Pires 1994, without their
   !> safeguard): solve W_JJ z_J = −q_J (dgbsv on the compressed band), drop from J the
   !> indices with z_j < 0, add those off J with (Wz + q)_i < 0, repeat. Accepted when both
   !> sets are empty within tol (z is then the LCP solution to round-off); after MAX_ROUNDS
   !> rounds z is left unchanged and PGS carries on.
   subroutine polish(wb, kw, q, z, tol, done)
      real(dp), intent(in) :: wb(:, :), q(:), tol
      integer, intent(in) :: kw
      real(dp), intent(inout) :: z(:)
      logical, intent(out) :: done
      integer, parameter :: MAX_ROUNDS = 8
      integer :: idx(size(q)), ipiv(size(q)), nj, i, j, k, l, n, info, round
      logical :: inj(size(q)), changed
      real(dp), allocatable :: ab(:, :)
      real(dp) :: zj(size(q)), zfull(size(q)), w, qscale, zscale
      n = size(q)
      done = .false.
      inj = z > 0.0_dp
      qscale = maxval(abs(q))
      allocate (ab(3*kw + 1, n))
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
end module martello_lcp
