!> The C door of a finished run's results (martello_run_history … martello_run_energy of
!> c/martello.h): copies out of the run's observer (martello_observer). Nothing is computed
!> here.
module martello_api_results
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_observer, only: tracks, observer_events
   use martello_run_quantities, only: NCOUNTERS, NENERGY, NEVENT
   use martello_registry, only: TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use martello_run, only: run_t
   use martello_api_handles, only: get_run
   implicit none
   private

contains

   integer(c_int) function c_run_history_shape(handle, rows, cols) bind(C, name='martello_run_history_shape')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: rows, cols
      type(run_t), pointer :: rp
      rp => get_run(handle)
      rows = 0; cols = 0
      c_run_history_shape = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rows = rp%results%nrec; cols = rp%results%ncol
      c_run_history_shape = MARTELLO_OK
   end function c_run_history_shape

   !> The history, one record after the other (C row-major rows × cols).
   integer(c_int) function c_run_history(handle, buf) bind(C, name='martello_run_history')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: buf(*)
      type(run_t), pointer :: rp
      integer :: nr, nc
      rp => get_run(handle)
      c_run_history = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      nr = rp%results%nrec; nc = rp%results%ncol
      if (nr > 0) buf(1:nr*nc) = reshape(rp%results%hist(:, 1:nr), [nr*nc])
      c_run_history = MARTELLO_OK
   end function c_run_history

   !> Contact phases: n on return; if contacts is not NULL also contact[n] (0-based) and
   !> values[n][6] = {t_on, t_off (−1: still open at the end), v_in, v_out, max δ, max P}.
   integer(c_int) function c_run_events(handle, n, contacts, values) bind(C, name='martello_run_events')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n
      type(c_ptr), value :: contacts, values
      type(run_t), pointer :: rp
      integer(c_int), pointer :: ic(:)
      real(c_double), pointer :: vals(:, :)
      integer :: nev
      rp => get_run(handle)
      n = 0
      c_run_events = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%ev)) then
         c_run_events = MARTELLO_OK; return
      end if
      call observer_events(rp%results, nev)
      n = nev
      if (nev > 0 .and. c_associated(contacts) .and. c_associated(values)) then
         call c_f_pointer(contacts, ic, [nev]); call c_f_pointer(values, vals, [NEVENT, nev])
         call observer_events(rp%results, nev, ic, vals)
      else if (nev > 0 .and. c_associated(contacts)) then
         call c_f_pointer(contacts, ic, [nev])
         call observer_events(rp%results, nev, contact=ic)
      else if (nev > 0 .and. c_associated(values)) then
         call c_f_pointer(values, vals, [NEVENT, nev])
         call observer_events(rp%results, nev, values=vals)
      end if
      c_run_events = MARTELLO_OK
   end function c_run_events

   !> counters[9] = {steps, rejected steps, Newton iterations, residual evaluations,
   !> factorizations, events, Jacobian evaluations, root-function evaluations, chatter}
   integer(c_int) function c_run_counters(handle, counters) bind(C, name='martello_run_counters')
      type(c_ptr), value :: handle
      integer(c_long_long), intent(out) :: counters(NCOUNTERS)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_counters = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      counters = rp%results%counters
      c_run_counters = MARTELLO_OK
   end function c_run_counters

   !> Per node and contact (c/martello.h): each output may be NULL (not written); what the
   !> run did not track is NaN (martello_run_set_tracking).
   integer(c_int) function c_run_peaks(handle, u_max, u_min, v_absmax, a_absmax, pen_max, &
                                       force_max, impacts, u_peak, t_peak) bind(C, name='martello_run_peaks')
      type(c_ptr), value :: handle, u_max, u_min, v_absmax, a_absmax, pen_max, force_max, &
                            impacts, u_peak, t_peak
      type(run_t), pointer :: rp
      integer(c_int), pointer :: ip(:)
      rp => get_run(handle)
      c_run_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%u_max)) return
      associate (r => rp%results)
         call put(u_max, r%u_max, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(u_min, r%u_min, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(v_absmax, r%v_absmax, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(a_absmax, r%a_absmax, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(u_peak, r%u_peak, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(t_peak, r%t_peak, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(pen_max, r%pen_max, r%n_contacts, tracks(r, TRACK_CONTACT_PEAKS))
         call put(force_max, r%force_max, r%n_contacts, tracks(r, TRACK_CONTACT_PEAKS))
         if (c_associated(impacts)) then
            call c_f_pointer(impacts, ip, [r%n_contacts]); ip = r%impacts
         end if
      end associate
      c_run_peaks = MARTELLO_OK
   end function c_run_peaks

   !> Per node: the largest |u| and its time (docs/results.md, u_absmax); NULL: not written.
   integer(c_int) function c_run_abs_peaks(handle, u_absmax, t_absmax) bind(C, name='martello_run_abs_peaks')
      type(c_ptr), value :: handle, u_absmax, t_absmax
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_abs_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%u_absmax)) return
      associate (r => rp%results)
         call put(u_absmax, r%u_absmax, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
         call put(t_absmax, r%t_absmax, r%n_nodes, tracks(r, TRACK_NODE_PEAKS))
      end associate
      c_run_abs_peaks = MARTELLO_OK
   end function c_run_abs_peaks

   !> The n values of a result array at the C pointer out unless NULL: src if tracked, else
   !> NaN.
   subroutine put(out, src, n, tracked)
      type(c_ptr), intent(in) :: out
      real(dp), intent(in) :: src(:)
      integer, intent(in) :: n
      logical, intent(in) :: tracked
      real(c_double), pointer :: x(:)
      if (.not. c_associated(out)) return
      call c_f_pointer(out, x, [n])
      if (tracked) then
         x = src(1:n)
      else
         x = ieee_value(1.0_dp, ieee_quiet_nan)
      end if
   end subroutine put

   !> energy[9] = {kinetic, recoverable, input, damping, plastic, contact, balance, initial,
   !> impact}; extra[4] = {max |balance| over the run, omega_max, dt_crit, t reached}
   integer(c_int) function c_run_energy(handle, energy, extra) bind(C, name='martello_run_energy')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: energy(NENERGY), extra(4)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_energy = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      energy = rp%results%energy
      extra = [rp%results%energy_balance_max, rp%results%omega_max, rp%results%dt_critical, &
               rp%results%t_end_reached]
      c_run_energy = MARTELLO_OK
   end function c_run_energy

   !> Per link: max |force| and max |elongation| over the run (NaN if not tracked); NULL: not
   !> written.
   integer(c_int) function c_run_link_peaks(handle, fmax, dumax) bind(C, name='martello_run_link_peaks')
      type(c_ptr), value :: handle, fmax, dumax
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_link_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%link_force_absmax)) return
      associate (r => rp%results)
         call put(fmax, r%link_force_absmax, r%n_links, tracks(r, TRACK_LINK_PEAKS))
         call put(dumax, r%link_du_absmax, r%n_links, tracks(r, TRACK_LINK_PEAKS))
      end associate
      c_run_link_peaks = MARTELLO_OK
   end function c_run_link_peaks

   !> Per tracked functional (martello_run_set_functionals): the largest and smallest value
   !> and their times (times −1: no sample); per pair the largest resultant and its time.
   integer(c_int) function c_run_functionals(handle, qmax, tmax, qmin, tmin, resmax, tres) &
      bind(C, name='martello_run_functionals')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: qmax(*), tmax(*), qmin(*), tmin(*), resmax(*), tres(*)
      type(run_t), pointer :: rp
      integer :: n, np
      rp => get_run(handle)
      c_run_functionals = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      associate (f => rp%results%fq)
         if (.not. allocated(f%q_max)) return
         n = f%n; np = size(f%res_max)
         qmax(1:n) = f%q_max; tmax(1:n) = f%t_max; qmin(1:n) = f%q_min; tmin(1:n) = f%t_min
         resmax(1:np) = f%res_max; tres(1:np) = f%t_res
      end associate
      c_run_functionals = MARTELLO_OK
   end function c_run_functionals

   !> The step trace (martello_run_set_trace, _set_trace_nodes): n, its grid points; with a
   !> non-NULL buf also buf(4 + m, n) = t, the traced contact's force, the kinetic and the
   !> recoverable energy, u of the m traced nodes.
   integer(c_int) function c_run_trace(handle, n, buf) bind(C, name='martello_run_trace')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n
      type(c_ptr), value :: buf
      real(c_double), pointer :: b(:, :)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_trace = MARTELLO_ERR_ARGUMENT
      n = 0
      if (.not. associated(rp)) return
      n = int(rp%results%ntrace, c_int)
      if (c_associated(buf) .and. n > 0) then
         call c_f_pointer(buf, b, [size(rp%results%trace, 1), int(n)])
         b = rp%results%trace(:, 1:n)
      end if
      c_run_trace = MARTELLO_OK
   end function c_run_trace
end module martello_api_results
