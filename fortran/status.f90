!> Status codes returned through the C door: 0 success, > 0 a result with a non-error
!> outcome, < 0 failure. Their names and meanings are the registry's table "status"
!> (fortran/registry.f90); tests/test_registry.py checks the enum of c/martello.h against it.
module martello_status
   use, intrinsic :: iso_fortran_env, only: error_unit
   use, intrinsic :: iso_c_binding, only: c_int
   use martello_kinds, only: dp
   implicit none
   private
   public :: out_of_memory, memory_message, REAL_BYTES, INT_BYTES, FIX_SMALLER_SCENE, sci
   public :: MARTELLO_OK, MARTELLO_ILL_CONDITIONED, MARTELLO_ROOT_FOUND, &
      MARTELLO_ERR_ARGUMENT, MARTELLO_ERR_MEMORY, MARTELLO_ERR_SINGULAR, &
      MARTELLO_ERR_NOT_CONVERGED, MARTELLO_ERR_DIVERGED, MARTELLO_ERR_UNSUPPORTED, &
      MARTELLO_ERR_UNSTABLE, MARTELLO_ERR_LAPACK, MARTELLO_ERR_STEP_UNDERFLOW, &
      MARTELLO_ERR_EXTERNAL, MARTELLO_ERR_STATE, MARTELLO_ERR_LIMIT, MARTELLO_ERR_INTERRUPTED

   integer, parameter :: MARTELLO_OK = 0
   integer, parameter :: MARTELLO_ILL_CONDITIONED = 1  !< solved, but digits were lost
   integer, parameter :: MARTELLO_ROOT_FOUND = 2       !< an event stopped the integration
   integer, parameter :: MARTELLO_ERR_ARGUMENT = -1
   integer, parameter :: MARTELLO_ERR_MEMORY = -2
   integer, parameter :: MARTELLO_ERR_SINGULAR = -3
   integer, parameter :: MARTELLO_ERR_NOT_CONVERGED = -4
   integer, parameter :: MARTELLO_ERR_DIVERGED = -5
   integer, parameter :: MARTELLO_ERR_UNSUPPORTED = -6
   integer, parameter :: MARTELLO_ERR_UNSTABLE = -7
   integer, parameter :: MARTELLO_ERR_LAPACK = -8
   integer, parameter :: MARTELLO_ERR_STEP_UNDERFLOW = -9
   integer, parameter :: MARTELLO_ERR_EXTERNAL = -10   !< GSL or SUNDIALS reported a failure
   integer, parameter :: MARTELLO_ERR_STATE = -11      !< call out of order (e.g. run before build)
   integer, parameter :: MARTELLO_ERR_LIMIT = -12      !< max_steps or max_wall reached
   integer, parameter :: MARTELLO_ERR_INTERRUPTED = -13 !< the caller's progress callback stopped it

   !> Bytes of one real(dp) and of one default integer: the amounts the out-of-memory
   !> message names are counted in these.
   real(dp), parameter :: REAL_BYTES = storage_size(1.0_dp)/8, INT_BYTES = storage_size(1)/8
   !> The fix of the out-of-memory message for arrays that grow with the scene.
   character(len=*), parameter :: FIX_SMALLER_SCENE = &
      'use a smaller scene (fewer nodes, links or contacts)'

contains

   !> An allocation failed (docs/behaviour.md "When memory runs out"): stat =
   !> MARTELLO_ERR_MEMORY and message = memory_message(what, bytes, fix). A caller with no
   !> status to return (stat absent) stops the process with that line instead.
   subroutine out_of_memory(what, bytes, fix, stat, message)
      character(len=*), intent(in) :: what, fix
      real(dp), intent(in) :: bytes
      integer, intent(out), optional :: stat
      character(len=*), intent(out), optional :: message
      interface
         !> C's exit: one line and status 1, where ERROR STOP would add a line of its own
         subroutine c_exit(code) bind(C, name='exit')
            import :: c_int
            integer(c_int), value :: code
         end subroutine c_exit
      end interface
      if (.not. present(stat)) then
         write (error_unit, '(a)') 'martello: error: '//memory_message(what, bytes, fix)
         flush (error_unit)
         call c_exit(1_c_int)
      end if
      stat = MARTELLO_ERR_MEMORY
      if (present(message)) message = memory_message(what, bytes, fix)
   end subroutine out_of_memory

   !> The one line of every allocation of the library that failed, Fortran and C alike:
   !> what could not be allocated, how much (bytes < 0: not known, an object GSL or SUNDIALS
   !> allocates inside), and what to change.
   function memory_message(what, bytes, fix) result(line)
      character(len=*), intent(in) :: what, fix
      real(dp), intent(in) :: bytes
      character(len=:), allocatable :: line
      character(len=32) :: amount
      if (bytes < 0.0_dp) then
         line = 'out of memory allocating '//what//': '//fix
         return
      else if (bytes >= 1.0e9_dp) then
         write (amount, '(f0.1,a)') bytes/1.0e9_dp, ' GB'
      else if (bytes >= 1.0e6_dp) then
         write (amount, '(f0.1,a)') bytes/1.0e6_dp, ' MB'
      else if (bytes >= 1.0e3_dp) then
         write (amount, '(f0.1,a)') bytes/1.0e3_dp, ' kB'
      else
         write (amount, '(i0,a)') nint(bytes), ' bytes'
      end if
      line = 'out of memory allocating '//what//' ('//trim(amount)//'): '//fix
   end function memory_message
   !> x in scientific notation with `digits` digits after the point, as messages give numbers:
   !> what ESw.d writes for it ("1.23450E-01", no padding), with the E of an exponent of
   !> three digits kept ("1.23450E-303"; ESw.d writes "1.23450-303", which reads as a
   !> subtraction).
   pure function sci(x, digits) result(text)
      real(dp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: text
      character(len=48) :: buf, edit
      integer :: e
      write (edit, '(a,i0,a)') '(es48.', max(0, min(digits, 30)), 'e3)'
      write (buf, edit) x
      text = trim(adjustl(buf))
      e = index(text, 'E', back=.true.)
      ! "E+012" -> "E+12": two digits as ESw.d gives when they suffice
      if (e > 0 .and. len(text) == e + 4) then
         if (text(e + 2:e + 2) == '0') text = text(:e + 1)//text(e + 3:)
      end if
   end function sci
end module martello_status
