!> Banded square matrices for the structural systems of chains: the effective stiffness
!> J = c_m M + c_k K_t + c_c C_t has the half-bandwidth kd of the model (1 for a chain
!> numbered in order). Storage is LAPACK's general-band layout for dgbsv (kl = ku = kd):
!> A(i,j) lives in ab(2kd+1+i−j, j), with kd extra rows for the LU fill. kd = 1 is solved by
!> a Thomas sweep (O(n), no pivoting: J is diagonally dominant when the tangents are ≥ 0),
!> falling back to dgbsv if a pivot collapses. Workspaces are allocated once, in band_init.
module martello_band_matrix
   use martello_kinds, only: dp
   use martello_lapack, only: dgbsv, dgbtrf, dgbtrs
   use martello_status, only: MARTELLO_OK, out_of_memory, REAL_BYTES, INT_BYTES, FIX_SMALLER_SCENE
   implicit none
   private
   public :: band_t, band_init, band_zero, band_add, band_add_pair, band_pin, band_solve, &
      band_matvec, band_get, band_factor, band_solve_factored

   type :: band_t
      integer :: n = 0, kd = 0
      real(dp), allocatable :: ab(:, :)
      real(dp), allocatable :: dl(:), d(:), du(:), rhs_copy(:)
      integer, allocatable :: ipiv(:)
      !> band_factor's method: 1 the Thomas pivots in d (multipliers in dl), 2 dgbtrf in ab
      integer :: factored = 0
   end type band_t


contains

   !> An n × n band of half-bandwidth kd, zero. stat, message: as martello_status
   !> out_of_memory if it cannot be allocated (absent: the process stops with its line).
   subroutine band_init(b, n, kd, stat, message)
      type(band_t), intent(out) :: b
      integer, intent(in) :: n, kd
      integer, intent(out), optional :: stat
      character(len=*), intent(out), optional :: message
      character(len=64) :: what
      integer :: st
      if (present(stat)) stat = MARTELLO_OK
      b%n = n; b%kd = kd
      allocate (b%ab(3*kd + 1, n), b%ipiv(n), b%dl(n), b%d(n), b%du(n), b%rhs_copy(n), stat=st)
      if (st /= 0) then
         write (what, '(a,i0,a,i0)') 'a band matrix of ', n, ' rows and half-bandwidth ', kd
         call out_of_memory(trim(what), REAL_BYTES*(3.0_dp*kd + 5)*n + INT_BYTES*n, &
                            FIX_SMALLER_SCENE, stat, message)
         return
      end if
      b%ab = 0.0_dp
   end subroutine band_init

   pure subroutine band_zero(b)
      type(band_t), intent(inout) :: b
      b%ab = 0.0_dp
   end subroutine band_zero

   pure subroutine band_add(b, i, j, val)
      type(band_t), intent(inout) :: b
      integer, intent(in) :: i, j
      real(dp), intent(in) :: val
      b%ab(2*b%kd + 1 + i - j, j) = b%ab(2*b%kd + 1 + i - j, j) + val
   end subroutine band_add

   pure real(dp) function band_get(b, i, j)
      type(band_t), intent(in) :: b
      integer, intent(in) :: i, j
      band_get = 0.0_dp
      if (abs(i - j) <= b%kd) band_get = b%ab(2*b%kd + 1 + i - j, j)
   end function band_get

   !> The stencil of a two-node element of stiffness s between nodes i and j (0 = ground):
   !> +s on both diagonals, −s off the diagonal.
   pure subroutine band_add_pair(b, i, j, s)
      type(band_t), intent(inout) :: b
      integer, intent(in) :: i, j
      real(dp), intent(in) :: s
      integer :: r
      r = 2*b%kd + 1
      if (i > 0) b%ab(r, i) = b%ab(r, i) + s
      if (j > 0) b%ab(r, j) = b%ab(r, j) + s
      if (i > 0 .and. j > 0) then
         b%ab(r + i - j, j) = b%ab(r + i - j, j) - s
         b%ab(r + j - i, i) = b%ab(r + j - i, i) - s
      end if
   end subroutine band_add_pair

   !> Replace row and column i by the identity: a fixed DOF (its increment is 0).
   pure subroutine band_pin(b, i)
      type(band_t), intent(inout) :: b
      integer, intent(in) :: i
      integer :: j, r
      r = 2*b%kd + 1
      do j = max(1, i - b%kd), min(b%n, i + b%kd)
         b%ab(r + i - j, j) = 0.0_dp      ! row i
         b%ab(r + j - i, i) = 0.0_dp      ! column i
      end do
      b%ab(r, i) = 1.0_dp
   end subroutine band_pin

   !> y = A x (A as assembled, before any solve).
   pure subroutine band_matvec(b, x, y)
      type(band_t), intent(in) :: b
      real(dp), intent(in) :: x(:)
      real(dp), intent(out) :: y(:)
      integer :: i, j, r, n
      r = 2*b%kd + 1
      n = b%n
      if (b%kd == 1 .and. n > 1) then     ! the chain case, unrolled
         y(1) = b%ab(r, 1)*x(1) + b%ab(r - 1, 2)*x(2)
         do i = 2, n - 1
            y(i) = b%ab(r + 1, i - 1)*x(i - 1) + b%ab(r, i)*x(i) + b%ab(r - 1, i + 1)*x(i + 1)
         end do
         y(n) = b%ab(r + 1, n - 1)*x(n - 1) + b%ab(r, n)*x(n)
         return
      end if
      do i = 1, b%n
         y(i) = 0.0_dp
         do j = max(1, i - b%kd), min(b%n, i + b%kd)
            y(i) = y(i) + b%ab(r + i - j, j)*x(j)
         end do
      end do
   end subroutine band_matvec

   !> Solve A x = rhs in place (rhs becomes x). A is destroyed. ok = .false. if singular.
   subroutine band_solve(b, rhs, ok)
      type(band_t), intent(inout) :: b
      real(dp), intent(inout) :: rhs(:)
      logical, intent(out) :: ok
      integer :: i, n, r, info
      real(dp) :: w
      n = b%n; r = 2*b%kd + 1
      ok = .true.
      select case (b%kd)
      case (0)
         if (any(b%ab(r, :) == 0.0_dp)) then
            ok = .false.; return
         end if
         rhs = rhs/b%ab(r, :)
      case (1)
         ! Thomas sweep on copies, so that dgbsv can take over from the intact matrix.
         b%d = b%ab(r, :)
         b%rhs_copy = rhs
         do i = 2, n
            if (abs(b%d(i - 1)) <= 1.0e-14_dp*abs(b%ab(r - 1, i))) exit
            w = b%ab(r + 1, i - 1)/b%d(i - 1)           ! A(i, i−1)/pivot
            b%d(i) = b%d(i) - w*b%ab(r - 1, i)           ! − w·A(i−1, i)
            rhs(i) = rhs(i) - w*rhs(i - 1)
         end do
         if (i <= n .or. b%d(n) == 0.0_dp) then
            rhs = b%rhs_copy
            call general()
            return
         end if
         rhs(n) = rhs(n)/b%d(n)
         do i = n - 1, 1, -1
            rhs(i) = (rhs(i) - b%ab(r - 1, i + 1)*rhs(i + 1))/b%d(i)
         end do
      case default
         call general()
      end select
   contains
      subroutine general()
         call dgbsv(n, b%kd, b%kd, 1, b%ab, size(b%ab, 1), b%ipiv, rhs, n, info)
         ok = info == 0
      end subroutine general
   end subroutine band_solve

   !> Factorise A in place, for any number of band_solve_factored calls (a Newton matrix kept
   !> while the tangents do not change): kd = 1 by the Thomas elimination (pivots in d,
   !> multipliers in dl; ab intact), falling back to dgbtrf where a pivot collapses, as
   !> band_solve; kd ≠ 1 by dgbtrf (ab becomes its LU). ok = .false. if singular.
   subroutine band_factor(b, ok)
      type(band_t), intent(inout) :: b
      logical, intent(out) :: ok
      integer :: i, n, r, info
      n = b%n; r = 2*b%kd + 1
      ok = .true.
      if (b%kd == 1) then
         b%d = b%ab(r, :)
         do i = 2, n
            if (abs(b%d(i - 1)) <= 1.0e-14_dp*abs(b%ab(r - 1, i))) exit
            b%dl(i) = b%ab(r + 1, i - 1)/b%d(i - 1)
            b%d(i) = b%d(i) - b%dl(i)*b%ab(r - 1, i)
         end do
         if (i > n .and. b%d(n) /= 0.0_dp) then
            b%factored = 1
            return
         end if
      end if
      if (b%kd == 0) then
         ok = all(b%ab(r, :) /= 0.0_dp)
         b%factored = 2
         return
      end if
      call dgbtrf(n, n, b%kd, b%kd, b%ab, size(b%ab, 1), b%ipiv, info)
      ok = info == 0
      b%factored = 2
   end subroutine band_factor

   !> Solve A x = rhs in place with band_factor's factors (A not changed).
   subroutine band_solve_factored(b, rhs)
      type(band_t), intent(inout) :: b
      real(dp), intent(inout) :: rhs(:)
      integer :: i, n, r, info
      n = b%n; r = 2*b%kd + 1
      if (b%kd == 0) then
         rhs = rhs/b%ab(r, :)
      else if (b%factored == 1) then
         do i = 2, n
            rhs(i) = rhs(i) - b%dl(i)*rhs(i - 1)
         end do
         rhs(n) = rhs(n)/b%d(n)
         do i = n - 1, 1, -1
            rhs(i) = (rhs(i) - b%ab(r - 1, i + 1)*rhs(i + 1))/b%d(i)
         end do
      else
         call dgbtrs('N', n, b%kd, b%kd, 1, b%ab, size(b%ab, 1), b%ipiv, rhs, n, info)
      end if
   end subroutine band_solve_factored
end module martello_band_matrix
