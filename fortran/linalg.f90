!> Dense and banded linear solves on LAPACK, with condition estimates. LAPACK's `info` is
!> translated into a status and a message here and nowhere else (as stdlib's handle_gesv_info).
!> Matrices are column-major (Fortran/LAPACK order).
module martello_linalg
   use martello_kinds, only: dp
   use martello_lapack, only: dpotrf, dpotrs, dpocon, dsytrf, dsytrs, dsycon, dlansy
   use martello_status, only: MARTELLO_OK, MARTELLO_ERR_SINGULAR, MARTELLO_ERR_LAPACK, out_of_memory, &
      REAL_BYTES, INT_BYTES, FIX_SMALLER_SCENE
   implicit none
   private
   public :: solve_spd, solve_symmetric_indefinite, lapack_status, tridiagonal_solve


contains

   !> The one place where LAPACK's info becomes a status and a message.
   subroutine lapack_status(routine, info, stat, msg)
      character(len=*), intent(in) :: routine
      integer, intent(in) :: info
      integer, intent(out) :: stat
      character(len=*), intent(inout) :: msg
      character(len=16) :: num
      write (num, '(i0)') abs(info)
      if (info == 0) then
         stat = MARTELLO_OK
      else if (info < 0) then
         stat = MARTELLO_ERR_LAPACK
         msg = routine//': argument '//trim(num)//' had an illegal value (a bug in martello)'
      else
         stat = MARTELLO_ERR_SINGULAR
         select case (routine)
         case ('dpotrf')
            msg = 'dpotrf: the system matrix is not positive definite (leading minor '//trim(num)// &
               ' failed): a node is not held by any link or active contact, or a penalty stiffness'// &
               ' swamps the rest of the matrix'
         case default
            msg = routine//': the system matrix is exactly singular (pivot '//trim(num)// &
               '): a node is not held by any link or active contact'
         end select
      end if
   end subroutine lapack_status

   !> Solve A x = b for symmetric positive definite A (Cholesky, dpotrf/dpotrs) and estimate
   !> the reciprocal 1-norm condition number with dpocon. A is overwritten; b becomes x.
   subroutine solve_spd(a, b, rcond, stat, msg)
      real(dp), intent(inout) :: a(:, :), b(:)
      real(dp), intent(out) :: rcond
      integer, intent(out) :: stat
      character(len=*), intent(inout) :: msg
      integer :: n, info
      real(dp) :: anorm
      real(dp), allocatable :: work(:)
      integer, allocatable :: iwork(:)

      n = size(a, 1)
      rcond = 1.0_dp
      stat = MARTELLO_OK
      if (n == 0) return
      allocate (work(3*n), iwork(n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the workspace of a Cholesky solve', (3*REAL_BYTES + INT_BYTES)*n, &
                            FIX_SMALLER_SCENE, stat, msg)
         return
      end if
      anorm = dlansy('1', 'U', n, a, n, work)
      call dpotrf('U', n, a, n, info)
      call lapack_status('dpotrf', info, stat, msg)
      if (stat /= MARTELLO_OK) return
      call dpocon('U', n, a, n, anorm, rcond, work, iwork, info)
      call dpotrs('U', n, 1, a, n, b, n, info)
      call lapack_status('dpotrs', info, stat, msg)
   end subroutine solve_spd

   !> Solve A x = b for symmetric indefinite A (Bunch–Kaufman, dsytrf/dsytrs), the KKT
   !> systems of Lagrange multipliers, with a dsycon condition estimate.
   subroutine solve_symmetric_indefinite(a, b, rcond, stat, msg)
      real(dp), intent(inout) :: a(:, :), b(:)
      real(dp), intent(out) :: rcond
      integer, intent(out) :: stat
      character(len=*), intent(inout) :: msg
      integer :: n, info, lwork
      real(dp) :: anorm, query(1)
      real(dp), allocatable :: work(:)
      integer, allocatable :: ipiv(:), iwork(:)

      n = size(a, 1)
      rcond = 1.0_dp
      stat = MARTELLO_OK
      if (n == 0) return
      lwork = 2*n
      allocate (ipiv(n), iwork(n), work(lwork), stat=stat)
      if (stat == 0) then
         anorm = dlansy('1', 'U', n, a, n, work)
         call dsytrf('U', n, a, n, ipiv, query, -1, info)
         lwork = max(2*n, int(query(1)))
         deallocate (work); allocate (work(lwork), stat=stat)
      end if
      if (stat /= 0) then
         call out_of_memory('the workspace of a symmetric indefinite solve', &
                            REAL_BYTES*lwork + 2*INT_BYTES*n, FIX_SMALLER_SCENE, stat, msg)
         return
      end if
      call dsytrf('U', n, a, n, ipiv, work, lwork, info)
      call lapack_status('dsytrf', info, stat, msg)
      if (stat /= MARTELLO_OK) return
      call dsycon('U', n, a, n, ipiv, anorm, rcond, work, iwork, info)
      call dsytrs('U', n, 1, a, n, ipiv, b, n, info)
      call lapack_status('dsytrs', info, stat, msg)
   end subroutine solve_symmetric_indefinite

   !> Thomas sweep for a tridiagonal system (sub l, diagonal d, super u), in place: b becomes x.
   !> No pivoting: used only on the effective stiffness of implicit steps, which is diagonally
   !> dominant for positive masses (M/βΔt² dominates), so elimination is stable. d is destroyed.
   pure subroutine tridiagonal_solve(l, d, u, b, ok)
      real(dp), intent(in) :: l(:), u(:)
      real(dp), intent(inout) :: d(:), b(:)
      logical, intent(out) :: ok
      integer :: i, n
      real(dp) :: w
      n = size(d)
      ok = .true.
      do i = 2, n
         if (d(i - 1) == 0.0_dp) then
            ok = .false.; return
         end if
         w = l(i)/d(i - 1)
         d(i) = d(i) - w*u(i - 1)
         b(i) = b(i) - w*b(i - 1)
      end do
      if (d(n) == 0.0_dp) then
         ok = .false.; return
      end if
      b(n) = b(n)/d(n)
      do i = n - 1, 1, -1
         b(i) = (b(i) - u(i)*b(i + 1))/d(i)
      end do
   end subroutine tridiagonal_solve
end module martello_linalg
