!> Real and integer kinds used by every martello kernel (one place, as in stdlib_kinds).
module martello_kinds
   use, intrinsic :: iso_fortran_env, only: real64, int32, int64
   implicit none
   private
   public :: dp, i4, i8

   !> Double precision: all mechanics is done in it; C sees it as `double`.
   integer, parameter :: dp = real64
   integer, parameter :: i4 = int32
   integer, parameter :: i8 = int64
end module martello_kinds
