!> The door between the kernels and the C integrators (c/martello_internal.h, not public):
!> the scene's topology, force evaluation, and the recording of a run's results.
module martello_api_internal
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model
   use martello_evaluator
   use martello_contact_laws, only: P_RESTITUTION
   use martello_integrator_settings, only: integrator_settings_t
   use martello_results
   use martello_run, only: run_t
   use martello_api_handles, only: get_model, get_run, get_eval
   implicit none
   private

contains

   integer(c_int) function c_model_topology(handle, n, nc, mass, fixed, con_a, con_b, scheme, &
                                            gap, restitution, ncoupling) bind(C, name='martello_model_topology')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n, nc, ncoupling
      type(c_ptr), value :: mass, fixed, con_a, con_b, scheme, gap, restitution
      type(model_t), pointer :: mp
      real(c_double), pointer :: pm(:), pg(:), pe(:)
      integer(c_int), pointer :: pf(:), pa(:), pb(:), ps(:)
      mp => get_model(handle)
      c_model_topology = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      n = mp%n; nc = mp%ncontact; ncoupling = mp%ncoupling
      if (c_associated(mass)) then
         call c_f_pointer(mass, pm, [n]); pm = mp%mass
      end if
      if (c_associated(fixed)) then
         call c_f_pointer(fixed, pf, [n]); pf = merge(1, 0, mp%fixed)
      end if
      if (nc > 0) then
         if (c_associated(con_a)) then
            call c_f_pointer(con_a, pa, [nc]); pa = mp%con_a(1:nc) - 1
         end if
         if (c_associated(con_b)) then
            call c_f_pointer(con_b, pb, [nc]); pb = mp%con_b(1:nc) - 1
         end if
         if (c_associated(scheme)) then
            call c_f_pointer(scheme, ps, [nc]); ps = mp%con_scheme(1:nc)
         end if
         if (c_associated(gap)) then
            call c_f_pointer(gap, pg, [nc]); pg = mp%con_gap(1:nc)
         end if
         if (c_associated(restitution)) then
            call c_f_pointer(restitution, pe, [nc]); pe = mp%con_par(P_RESTITUTION, 1:nc)
         end if
      end if
      c_model_topology = MARTELLO_OK
   end function c_model_topology

   !> Initial displacements and velocities of the nodes (fixed nodes: u0, v = 0).
   integer(c_int) function c_model_initial_state(handle, u0, v0) bind(C, name='martello_model_initial_state')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u0(*), v0(*)
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_initial_state = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      u0(1:mp%n) = mp%u0
      v0(1:mp%n) = merge(0.0_dp, mp%v0, mp%fixed)
      c_model_initial_state = MARTELLO_OK
   end function c_model_initial_state

   !> The force of every penalty contact at the last evaluation (0 for other schemes).
   integer(c_int) function c_eval_contact_forces(handle, force) bind(C, name='martello_eval_contact_forces')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: force(*)
      type(evaluator_t), pointer :: ep
      integer :: nc
      ep => get_eval(handle)
      c_eval_contact_forces = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      nc = ep%m%ncontact
      force(1:nc) = merge(ep%ms%con_f_trial(1:nc), 0.0_dp, ep%ms%is_penalty(1:nc))
      c_eval_contact_forces = MARTELLO_OK
   end function c_eval_contact_forces

   integer(c_int) function c_eval_create(mhandle, handle) bind(C, name='martello_eval_create')
      type(c_ptr), value :: mhandle
      type(c_ptr), intent(out) :: handle
      type(model_t), pointer :: mp
      type(evaluator_t), pointer :: ep
      handle = c_null_ptr
      mp => get_model(mhandle)
      c_eval_create = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      allocate (ep)
      call evaluator_init(ep, mp)
      handle = c_loc(ep)
      c_eval_create = MARTELLO_OK
   end function c_eval_create

   subroutine c_eval_free(handle) bind(C, name='martello_eval_free')
      type(c_ptr), intent(inout) :: handle
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      if (associated(ep)) deallocate (ep)
      handle = c_null_ptr
   end subroutine c_eval_free

   integer(c_int) function c_eval_acceleration(handle, t, u, v, a) bind(C, name='martello_eval_acceleration')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: a(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_acceleration = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_acceleration(ep, t, u(1:ep%m%n), v(1:ep%m%n), a(1:ep%m%n), ok)
      c_eval_acceleration = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_acceleration

   integer(c_int) function c_eval_forces(handle, t, u, v, fint, fext) bind(C, name='martello_eval_forces')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: fint(*), fext(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_forces = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_forces(ep, t, u(1:ep%m%n), v(1:ep%m%n), fint(1:ep%m%n), fext(1:ep%m%n))
      c_eval_forces = MARTELLO_OK
   end function c_eval_forces

   integer(c_int) function c_eval_solve_mass(handle, x) bind(C, name='martello_eval_solve_mass')
      type(c_ptr), value :: handle
      real(c_double), intent(inout) :: x(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_solve_mass = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_solve_mass(ep, x(1:ep%m%n), ok)
      c_eval_solve_mass = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_solve_mass

   integer(c_int) function c_eval_contacts(handle, u, v, pen, rate) bind(C, name='martello_eval_contacts')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: pen(*), rate(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_contacts = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_contacts(ep, u(1:ep%m%n), v(1:ep%m%n), pen(1:ep%m%ncontact), rate(1:ep%m%ncontact))
      c_eval_contacts = MARTELLO_OK
   end function c_eval_contacts

   integer(c_int) function c_eval_commit(handle, u, v) bind(C, name='martello_eval_commit')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_commit = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_commit(ep, u(1:ep%m%n), v(1:ep%m%n))
      c_eval_commit = MARTELLO_OK
   end function c_eval_commit

   integer(c_int) function c_eval_energy(handle, u, v, kinetic, recoverable) bind(C, name='martello_eval_energy')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: kinetic, recoverable
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_energy = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_energy(ep, u(1:ep%m%n), v(1:ep%m%n), kinetic, recoverable)
      c_eval_energy = MARTELLO_OK
   end function c_eval_energy

   integer(c_int) function c_run_settings(handle, s) bind(C, name='martello_run_settings')
      type(c_ptr), value :: handle
      type(integrator_settings_t), intent(out) :: s
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_settings = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      s = rp%settings
      c_run_settings = MARTELLO_OK
   end function c_run_settings

   integer(c_int) function c_run_track(handle, t, u, v, a, pen, force) bind(C, name='martello_run_track')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), pen(*), force(*)
      type(run_t), pointer :: rp
      integer :: n, nc
      rp => get_run(handle)
      c_run_track = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      n = size(rp%results%u_max); nc = size(rp%results%pen_max)
      call results_track(rp%results, t, u(1:n), v(1:n), a(1:n), pen(1:nc), force(1:nc))
      c_run_track = MARTELLO_OK
   end function c_run_track

   integer(c_int) function c_run_record(handle, t, u, v, a, pen, force, energy) bind(C, name='martello_run_record')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), pen(*), force(*), energy(NENERGY)
      type(run_t), pointer :: rp
      integer :: n, nc
      rp => get_run(handle)
      c_run_record = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      n = size(rp%results%u_max); nc = size(rp%results%pen_max)
      call results_record(rp%results, t, u(1:n), v(1:n), a(1:n), pen(1:nc), force(1:nc), energy)
      rp%results%energy = energy
      rp%results%energy_balance_max = max(rp%results%energy_balance_max, abs(energy(E_BALANCE)))
      c_run_record = MARTELLO_OK
   end function c_run_record

   integer(c_int) function c_run_add_event(handle, contact, values) bind(C, name='martello_run_add_event')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      real(c_double), intent(in) :: values(NEVENT)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_add_event = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (contact < 0 .or. contact >= size(rp%results%impacts)) return
      call results_add_event(rp%results, int(contact) + 1, values)
      rp%results%impacts(contact + 1) = rp%results%impacts(contact + 1) + 1
      c_run_add_event = MARTELLO_OK
   end function c_run_add_event

   integer(c_int) function c_run_add_counts(handle, inc) bind(C, name='martello_run_add_counts')
      type(c_ptr), value :: handle
      integer(c_long_long), intent(in) :: inc(NCOUNTERS)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_add_counts = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%counters = rp%results%counters + inc
      c_run_add_counts = MARTELLO_OK
   end function c_run_add_counts

   integer(c_int) function c_run_set_message(handle, msg) bind(C, name='martello_run_set_message')
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: msg(*)
      type(run_t), pointer :: rp
      integer :: i
      rp => get_run(handle)
      c_run_set_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%message = ''
      do i = 1, len(rp%results%message)
         if (msg(i) == c_null_char) exit
         rp%results%message(i:i) = msg(i)
      end do
      c_run_set_message = MARTELLO_OK
   end function c_run_set_message

   integer(c_int) function c_run_finish(handle, t_reached, energy, balance_max) bind(C, name='martello_run_finish')
      type(c_ptr), value :: handle
      real(c_double), value :: t_reached, balance_max
      real(c_double), intent(in) :: energy(NENERGY)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_finish = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%t_end_reached = t_reached
      rp%results%energy = energy
      rp%results%energy_balance_max = max(rp%results%energy_balance_max, balance_max)
      c_run_finish = MARTELLO_OK
   end function c_run_finish
end module martello_api_internal
