!> The C door of the run handle (martello_run_create … martello_dynamic_run of c/martello.h):
!> converts arguments and calls martello_run, where validation and dispatch live.
module martello_api_run
   use, intrinsic :: iso_c_binding
   use martello_status
   use martello_model, only: model_t
   use martello_integrator_settings, only: integrator_settings_t, settings_default, settings_check
   use martello_run, only: run_t, run_dynamic
   use martello_registry, only: TRACK_ALL
   use martello_api_handles, only: get_model, get_run, copy_message
   implicit none
   private

contains

   integer(c_int) function c_run_create(handle) bind(C, name='martello_run_create')
      type(c_ptr), intent(out) :: handle
      type(run_t), pointer :: rp
      integer :: stat
      handle = c_null_ptr
      allocate (rp, stat=stat)
      if (stat /= 0) then
         c_run_create = MARTELLO_ERR_MEMORY; return
      end if
      allocate (rp%out_nodes(0), rp%out_contacts(0), rp%out_links(0))
      handle = c_loc(rp)
      c_run_create = MARTELLO_OK
   end function c_run_create

   subroutine c_run_free(handle) bind(C, name='martello_run_free')
      type(c_ptr), intent(inout) :: handle
      type(run_t), pointer :: rp
      rp => get_run(handle)
      if (associated(rp)) deallocate (rp)
      handle = c_null_ptr
   end subroutine c_run_free

   !> The registry's default settings of integrator kind (MARTELLO_INT_*).
   integer(c_int) function c_settings_default(kind, s) bind(C, name='martello_settings_default')
      integer(c_int), value :: kind
      type(integrator_settings_t), intent(out) :: s
      integer :: stat
      call settings_default(int(kind), s, stat)
      c_settings_default = stat
   end function c_settings_default

   !> Validate the settings (settings_check: the only place) and keep them for the run.
   integer(c_int) function c_run_set_settings(handle, s) bind(C, name='martello_run_set_settings')
      type(c_ptr), value :: handle
      type(integrator_settings_t), intent(in) :: s
      type(run_t), pointer :: rp
      integer :: stat
      rp => get_run(handle)
      c_run_set_settings = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      call settings_check(s, rp%results%message, stat)
      c_run_set_settings = stat
      if (stat /= MARTELLO_OK) return
      rp%settings = s
      rp%configured = .true.
   end function c_run_set_settings

   !> Which nodes and contacts the history records (0-based); the peaks cover all of them.
   integer(c_int) function c_run_set_outputs(handle, nn, nodes, nc, contacts) &
      bind(C, name='martello_run_set_outputs')
      type(c_ptr), value :: handle
      integer(c_int), value :: nn, nc
      integer(c_int), intent(in) :: nodes(*), contacts(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_outputs = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. nn < 0 .or. nc < 0) return
      rp%out_nodes = nodes(1:nn) + 1
      rp%out_contacts = contacts(1:nc) + 1
      c_run_set_outputs = MARTELLO_OK
   end function c_run_set_outputs

   !> Which links the history records (0-based): their force and elongation.
   integer(c_int) function c_run_set_link_outputs(handle, nl, links) bind(C, name='martello_run_set_link_outputs')
      type(c_ptr), value :: handle
      integer(c_int), value :: nl
      integer(c_int), intent(in) :: links(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_link_outputs = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. nl < 0) return
      rp%out_links = links(1:nl) + 1
      c_run_set_link_outputs = MARTELLO_OK
   end function c_run_set_link_outputs

   !> Linear functionals q = R·u of the state the run tracks at every accepted sample
   !> (docs/results.md, "Frames and buildings"): n rows of R in compressed rows (ptr[n+1],
   !> col[ptr[n]] nodes, val; 0-based) and np pairs of rows (pairs[2 np]) whose resultant
   !> √(q_a² + q_b²) is tracked; n = 0: none.
   integer(c_int) function c_run_set_functionals(handle, n, ptr, col, val, np, pairs) &
      bind(C, name='martello_run_set_functionals')
      type(c_ptr), value :: handle
      integer(c_int), value :: n, np
      integer(c_int), intent(in) :: ptr(*), col(*), pairs(*)
      real(c_double), intent(in) :: val(*)
      type(run_t), pointer :: rp
      integer :: nnz
      rp => get_run(handle)
      c_run_set_functionals = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. n < 0 .or. np < 0) return
      nnz = 0
      if (n > 0) nnz = ptr(n + 1)
      if (n > 0) then
         if (ptr(1) /= 0 .or. any(ptr(2:n + 1) < ptr(1:n))) return
      end if
      if (np > 0) then
         if (any(pairs(1:2*np) < 0 .or. pairs(1:2*np) >= n)) return
      end if
      rp%fq%n = int(n)
      rp%fq%ptr = ptr(1:n + 1) + 1
      rp%fq%col = col(1:nnz) + 1
      rp%fq%val = val(1:nnz)
      rp%fq%pair = reshape(pairs(1:2*np) + 1, [2, int(np)])
      c_run_set_functionals = MARTELLO_OK
   end function c_run_set_functionals

   !> Every contact's phases are listed while the model has at most max_contacts contacts
   !> (< 0: always); past it the output contacts' (martello_run_set_outputs), and the
   !> others keep their first and last phase (docs/results.md).
   integer(c_int) function c_run_set_phase_lists(handle, max_contacts) &
      bind(C, name='martello_run_set_phase_lists')
      type(c_ptr), value :: handle
      integer(c_int), value :: max_contacts
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_phase_lists = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%phase_lists = int(max_contacts)
      c_run_set_phase_lists = MARTELLO_OK
   end function c_run_set_phase_lists

   !> The contact (0-based; < 0: none, the default) whose force the step trace holds, with
   !> the kinetic and recoverable energies, at every grid point (martello_run_trace).
   integer(c_int) function c_run_set_trace(handle, contact) bind(C, name='martello_run_set_trace')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_trace = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%trace_contact = max(int(contact) + 1, 0)
      c_run_set_trace = MARTELLO_OK
   end function c_run_set_trace

   !> The nodes (0-based, n of them; default none) whose displacement the step trace holds
   !> after the contact's force and the energies (martello_run_trace).
   integer(c_int) function c_run_set_trace_nodes(handle, n, nodes) &
      bind(C, name='martello_run_set_trace_nodes')
      type(c_ptr), value :: handle
      integer(c_int), value :: n
      integer(c_int), intent(in) :: nodes(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_trace_nodes = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. n < 0) return
      rp%trace_nodes = nodes(1:n) + 1
      c_run_set_trace_nodes = MARTELLO_OK
   end function c_run_set_trace_nodes

   !> What the run tracks: an OR of MARTELLO_TRACK_* (default MARTELLO_TRACK_ALL).
   integer(c_int) function c_run_set_tracking(handle, what) bind(C, name='martello_run_set_tracking')
      type(c_ptr), value :: handle
      integer(c_int), value :: what
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_tracking = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (what < 0 .or. iand(int(what), not(TRACK_ALL)) /= 0) then
         rp%results%message = 'set_tracking: an OR of MARTELLO_TRACK_* flags is needed'; return
      end if
      rp%tracking = int(what)
      c_run_set_tracking = MARTELLO_OK
   end function c_run_set_tracking

   !> The progress callback of the run (c/martello.h martello_progress_fn), called with
   !> user about four times a second while it runs; a NULL callback removes it.
   integer(c_int) function c_run_set_progress(handle, callback, user) &
      bind(C, name='martello_run_set_progress')
      type(c_ptr), value :: handle
      type(c_funptr), value :: callback
      type(c_ptr), value :: user
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_progress = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%progress = callback; rp%progress_user = user
      c_run_set_progress = MARTELLO_OK
   end function c_run_set_progress

   integer(c_int) function c_dynamic_run(mhandle, rhandle) bind(C, name='martello_dynamic_run')
      type(c_ptr), value :: mhandle, rhandle
      type(model_t), pointer :: mp
      type(run_t), pointer :: rp
      integer :: stat
      mp => get_model(mhandle); rp => get_run(rhandle)
      c_dynamic_run = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp) .or. .not. associated(rp)) return
      call run_dynamic(mp, rp, stat)
      c_dynamic_run = stat
   end function c_dynamic_run

   integer(c_int) function c_run_message(handle, buf, buflen) bind(C, name='martello_run_message')
      type(c_ptr), value :: handle
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. buflen < 1) return
      call copy_message(rp%results%message, buf, buflen)
      c_run_message = MARTELLO_OK
   end function c_run_message
end module martello_api_run
