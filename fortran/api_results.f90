!> The C door of a finished run's results (martello_run_history … martello_run_energy of
!> c/martello.h): copies out of the run's observer (martello_observer). Nothing is computed
!> here.
module martello_api_results
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_observer, only: NCOUNTERS, NENERGY, NEVENT, tracks, TRACK_NODE_PEAKS, &
      TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS, observer_events
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

   integer(c_int) function c_run_peaks(handle, u_max, u_min, v_absmax, a_absmax, pen_max, &
                                       force_max, impacts, u_peak, t_peak) bind(C, name='martello_run_peaks')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u_max(*), u_min(*), v_absmax(*), a_absmax(*), pen_max(*), &
                                     force_max(*), u_peak(*), t_peak(*)
      integer(c_int), intent(out) :: impacts(*)
      type(run_t), pointer :: rp
      integer :: n, nc
      real(dp) :: nan
      rp => get_run(handle)
      c_run_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%u_max)) return
      n = rp%results%n_nodes; nc = rp%results%n_contacts
      nan = ieee_value(1.0_dp, ieee_quiet_nan)
      ! what the run did not track: NaN (martello_run_set_tracking)
      if (tracks(rp%results, TRACK_NODE_PEAKS)) then
         u_max(1:n) = rp%results%u_max; u_min(1:n) = rp%results%u_min
         v_absmax(1:n) = rp%results%v_absmax; a_absmax(1:n) = rp%results%a_absmax
         u_peak(1:n) = rp%results%u_peak; t_peak(1:n) = rp%results%t_peak
      else
         u_max(1:n) = nan; u_min(1:n) = nan; v_absmax(1:n) = nan; a_absmax(1:n) = nan
         u_peak(1:n) = nan; t_peak(1:n) = nan
      end if
      if (tracks(rp%results, TRACK_CONTACT_PEAKS)) then
         pen_max(1:nc) = rp%results%pen_max; force_max(1:nc) = rp%results%force_max
      else
         pen_max(1:nc) = nan; force_max(1:nc) = nan
      end if
      impacts(1:nc) = rp%results%impacts
      c_run_peaks = MARTELLO_OK
   end function c_run_peaks

   !> Per node: the largest |u| and its time (docs/results.md, u_absmax)
   integer(c_int) function c_run_abs_peaks(handle, u_absmax, t_absmax) bind(C, name='martello_run_abs_peaks')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u_absmax(*), t_absmax(*)
      type(run_t), pointer :: rp
      integer :: n
      rp => get_run(handle)
      c_run_abs_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%u_absmax)) return
      n = rp%results%n_nodes
      if (tracks(rp%results, TRACK_NODE_PEAKS)) then
         u_absmax(1:n) = rp%results%u_absmax; t_absmax(1:n) = rp%results%t_absmax
      else
         u_absmax(1:n) = ieee_value(1.0_dp, ieee_quiet_nan); t_absmax(1:n) = u_absmax(1:n)
      end if
      c_run_abs_peaks = MARTELLO_OK
   end function c_run_abs_peaks

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

   !> Per link: max |force| and max |elongation| over the run (NaN if not tracked).
   integer(c_int) function c_run_link_peaks(handle, fmax, dumax) bind(C, name='martello_run_link_peaks')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: fmax(*), dumax(*)
      type(run_t), pointer :: rp
      integer :: nl
      rp => get_run(handle)
      c_run_link_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%link_force_absmax)) return
      nl = rp%results%n_links
      if (tracks(rp%results, TRACK_LINK_PEAKS)) then
         fmax(1:nl) = rp%results%link_force_absmax; dumax(1:nl) = rp%results%link_du_absmax
      else
         fmax(1:nl) = ieee_value(1.0_dp, ieee_quiet_nan); dumax(1:nl) = fmax(1:nl)
      end if
      c_run_link_peaks = MARTELLO_OK
   end function c_run_link_peaks
end module martello_api_results
