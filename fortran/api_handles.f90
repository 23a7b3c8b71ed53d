!> Handles of the C API: an opaque C pointer ↔ the Fortran object it stands for, and the
!> NUL-terminated message copy every door uses. A null handle maps to a null pointer, which
!> each door turns into MARTELLO_ERR_ARGUMENT.
module martello_api_handles
   use, intrinsic :: iso_c_binding
   use martello_model, only: model_t
   use martello_run, only: run_t
   use martello_evaluator, only: evaluator_t
   use martello_observer, only: observer_t
   use martello_status, only: out_of_memory, memory_message, FIX_SMALLER_SCENE
   implicit none
   private
   public :: get_model, get_run, get_eval, get_observer, copy_message, from_c_string

contains

   !> Handle → model pointer; a null handle is an argument error.
   function get_model(handle) result(mp)
      type(c_ptr), value :: handle
      type(model_t), pointer :: mp
      mp => null()
      if (c_associated(handle)) call c_f_pointer(handle, mp)
   end function get_model

   function get_run(handle) result(rp)
      type(c_ptr), value :: handle
      type(run_t), pointer :: rp
      rp => null()
      if (c_associated(handle)) call c_f_pointer(handle, rp)
   end function get_run

   function get_eval(handle) result(ep)
      type(c_ptr), value :: handle
      type(evaluator_t), pointer :: ep
      ep => null()
      if (c_associated(handle)) call c_f_pointer(handle, ep)
   end function get_eval

   !> The observer of a run (martello_run_observer points into its run).
   function get_observer(handle) result(op)
      type(c_ptr), value :: handle
      type(observer_t), pointer :: op
      op => null()
      if (c_associated(handle)) call c_f_pointer(handle, op)
   end function get_observer
   !> A NUL-terminated C string as Fortran text (at most maxlen characters).
   function from_c_string(cstr, maxlen) result(s)
      character(kind=c_char), intent(in) :: cstr(*)
      integer, intent(in) :: maxlen
      character(len=:), allocatable :: s
      integer :: n, st
      n = 0
      do while (n < maxlen)
         if (cstr(n + 1) == c_null_char) exit
         n = n + 1
      end do
      ! a name of at most maxlen characters: no status to return from inside an expression
      allocate (character(len=n) :: s, stat=st)
      if (st /= 0) call out_of_memory('a name passed through the C API', real(n, c_double), &
                                      'free memory in the calling program')
      s = transfer(cstr(1:n), s)
   end function from_c_string

   !> Copy msg into buf (NUL-terminated, truncated to buflen − 1 characters).
   subroutine copy_message(msg, buf, buflen)
      character(len=*), intent(in) :: msg
      integer(c_int), intent(in) :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      integer :: i, n
      n = min(len_trim(msg), int(buflen) - 1)
      do i = 1, n
         buf(i) = msg(i:i)
      end do
      buf(n + 1) = c_null_char
   end subroutine copy_message

   !> The out-of-memory line of the C integrators (c/martello_internal.h): the kernels'
   !> wording (martello_status memory_message), so that every allocation says it alike.
   !> fix: NULL for FIX_SMALLER_SCENE.
   subroutine c_memory_message(what, bytes, fix, buf, buflen) bind(C, name='martello_memory_message')
      character(kind=c_char), intent(in) :: what(*)
      real(c_double), value :: bytes
      type(c_ptr), value :: fix
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      integer, parameter :: MAXLEN = 256
      character(kind=c_char), pointer :: cfix(:)
      if (c_associated(fix)) then
         call c_f_pointer(fix, cfix, [MAXLEN])
         call copy_message(memory_message(from_c_string(what, MAXLEN), bytes, &
                                          from_c_string(cfix, MAXLEN)), buf, buflen)
      else
         call copy_message(memory_message(from_c_string(what, MAXLEN), bytes, FIX_SMALLER_SCENE), &
                           buf, buflen)
      end if
   end subroutine c_memory_message
end module martello_api_handles
