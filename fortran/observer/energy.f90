!> The observer's energy terms and divergence test (docs/run-layer.md "The observer"), one
!> split for every method:
!>     balance = E_0 + W_ext − KE − E_rec − W_damp − D_plastic − D_contact − D_impact
!> the works accumulated from the increments the methods hand over, KE and E_rec evaluated
!> at the committed state where needed; and the start of a run, which sizes the observer's
!> working state.
submodule (martello_observer) energy
   use martello_assembly, only: kinetic_energy, recoverable_energy, mass_times
   use martello_element_rows, only: row_dot
   use martello_integrator_settings, only: integrator_name
   use martello_registry, only: TRACK_NODE_PEAKS, TRACK_CONTACT_PEAKS, TRACK_PHASES
   use martello_run_quantities, only: E_KINETIC, E_RECOVERABLE, E_INPUT, E_DAMPING, E_PLASTIC, &
      E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none

   !> Energy the contacts and impacts may create, as a share of the initial energy + input
   !> work, before the run is a failure: far above what the catalogue's fixed steps leave
   !> (≤ 1e-4: the trapezoidal work of a contact closing within a step), far below a
   !> realised restitution past 1 (e = 1.1 creates 21 % of the impact's energy).
   real(dp), parameter :: CREATED_BOUND = 1.0e-2_dp
   !> Energy [J] below which a state is at rest to round-off: neither divergence test fires
   !> while the energies it compares stay under it (a mass held against a stop by its load
   !> jitters at ~1e-41 J; a milligram moving at a nanometre per second has 5e-25 J).
   real(dp), parameter :: ENERGY_FLOOR = 1.0e-30_dp

contains

   !> The state at t = 0, before its first sample: the initial energies the balance starts
   !> from, and a phase opened at t = 0 for every penalty contact closed there.
   !> energy_interval: samples between energy evaluations (the strategy's choice: 16 for
   !> cheap fixed steps, 1 for adaptive ones); advice ends a divergence message; ke_aMa: the
   !> method conserves ½vᵀMv − ke_aMa·aᵀMa (Verlet; 0 for the others).
   !> energies = [kinetic, links, contacts]: a method that keeps its own element states (no
   !> ms, one that measures itself through observer_block) hands them, and has opened the
   !> phases at t = 0 itself.
   !> The observer's working arrays are allocated here, none later: stat =
   !> MARTELLO_ERR_MEMORY (o%message its line) if they cannot be.
   module procedure observer_begin
      real(dp) :: e_kin
      integer :: c
      character(len=64) :: what
      call located_peak_state(o, m%n, present(energies), stat)
      ! the link maxima per node and pair of a method that measures itself
      if (stat == 0 .and. present(energies)) call block_maxima(o, m, stat)
      ! the scratch vector of the energies this observer evaluates itself (kinetic_correction:
      ! ke_aMa /= 0)
      if (stat == 0 .and. .not. allocated(o%work) .and. (.not. present(energies) .or. ke_aMa /= 0.0_dp)) &
         allocate (o%work(0:m%n), stat=stat)
      if (stat /= 0) then
         write (what, '(a,i0,a)') 'the working state of the results of a run of ', m%n, ' nodes'
         call out_of_memory(trim(what), REAL_BYTES*(12.0_dp*m%n + 2.0_dp*size(o%ph_open) + 2), &
                            FIX_SMALLER_SCENE, stat, o%message)
         return
      end if
      if (present(energies)) then
         e_kin = energies(1); o%e_links0 = energies(2); o%e_cont0 = energies(3)
      else
         if (o%smooth_steps) then
            o%con_rows = m%con; o%has_con_rows = .true.
         end if
         do c = 1, m%ncontact
            if (ms%con_on(c)) call observer_open_phase(o, c, 0.0_dp, row_dot(m%con, c, v))
            ! the force and its rate the first step's located peaks start from
            if (allocated(o%c_prev_f)) &
               call contact_force_rate(m, ms, c, row_dot(m%con, c, v), &
                                       row_dot(m%con, c, a), o%c_prev_f(c), o%c_prev_fr(c))
         end do
         e_kin = kinetic_energy(m, v, o%work)
         call recoverable_energy(m, ms, u, o%e_links0, o%e_cont0)
      end if
      o%e0 = e_kin + o%e_links0 + o%e_cont0
      o%ke_aMa = ke_aMa
      ! the balance starts from the method's conserved energy e0 − ke_corr
      o%ke_corr0 = o%e0 - (o%e0 - kinetic_correction(o, m, a))
      o%energy_interval = max(energy_interval, 1)
      o%advice = advice
   end procedure observer_begin

   !> The working state of the located peaks of a smooth fixed-step method (smooth_steps):
   !> the phase change times per node and the candidates of |a| where node peaks are
   !> tracked, and, for a method that measures through observer_sample (not folded: the
   !> general path), the contact forces and rates at the previous sample where a contact
   !> peak or phase is tracked.
   subroutine located_peak_state(o, n, folded, st)
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: n
      logical, intent(in) :: folded
      integer, intent(out) :: st
      integer :: nn, nc
      st = 0
      if (.not. o%smooth_steps) return
      nn = merge(n, 0, tracks(o, TRACK_NODE_PEAKS))
      allocate (o%node_change(0:nn), o%a_m2(nn), o%a_m1(nn), o%a_0(nn), o%a_p1(nn), o%a_gen(nn), &
                o%pend1(nn), o%pend2(nn), o%a_back(nn), stat=st)
      if (st /= 0) return
      o%node_change = -huge(1.0_dp)
      o%a_back = 0.0_dp
      if (folded .or. .not. (tracks(o, TRACK_CONTACT_PEAKS) .or. tracks(o, TRACK_PHASES))) return
      nc = size(o%ph_open)
      allocate (o%c_prev_f(nc), o%c_prev_fr(nc), source=0.0_dp, stat=st)
   end subroutine located_peak_state

   !> Work increments of one step [J]: external, of the dampers, of the other links and of
   !> the penalty contacts (a fixed step: mech_commit's trapezoidal works), and the kinetic
   !> energy impulses took out. A method that integrates the works along its solution (the C
   !> integrators) may hand the total internal work instead of the dampers': damping is then
   !> internal − links − contact.
   module procedure observer_work
      if (present(external)) then
         o%w_ext = o%w_ext + external; o%w_abs = o%w_abs + abs(external)
         o%w_last = external
      end if
      if (present(internal)) then
         o%d_damp = o%d_damp + (internal - links - contact)
      else if (present(damping)) then
         o%d_damp = o%d_damp + damping
      end if
      if (present(links)) o%d_links = o%d_links + links
      if (present(contact)) o%d_contact = o%d_contact + contact
      if (present(impact)) o%d_impact = o%d_impact + impact
   end procedure observer_work

   !> ke_aMa·aᵀMa: velocity Verlet conserves ½vᵀMv − (h²/8)aᵀMa exactly against trapezoidal
   !> work (the a-terms of ΔKE telescope), so its balance is an identity to round-off, like
   !> average acceleration's (docs/integrators.md "energy balance").
   real(dp) function kinetic_correction(o, m, a) result(kc)
      type(observer_t), intent(inout) :: o
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: a(0:)
      kc = 0.0_dp
      if (o%ke_aMa == 0.0_dp) return
      call mass_times(m, a, o%work)
      kc = o%ke_aMa*dot_product(a(1:m%n), o%work(1:m%n))
   end function kinetic_correction

   !> Whether the next sample, at grid point k, evaluates the energy terms: on the energy
   !> grid (energy_grid) and where recorded, for the history row (a method that hands its
   !> energies to the sample computes them then).
   module procedure observer_energy_due
      due = energy_grid(o, k) .or. recorded(o, k) .or. traced(o, k)
   end procedure observer_energy_due

   !> Whether the next sample, at grid point k (−1: off the grid), is on the energy grid,
   !> where the largest |balance| is taken and the divergence test made: t = 0, every
   !> energy_interval-th grid point (of a sample off the grid: every energy_interval-th
   !> sample), the last grid point and once a work is not finite. Never the recorded rows as
   !> such: no result depends on how the run is recorded (docs/invariance.md).
   module procedure energy_grid
      grid = k == 0 .or. k >= o%n_grid .or. &
             mod(merge(k, o%nsamples + 1, k >= 0), int(o%energy_interval, i8)) == 0 .or. &
             .not. ieee_is_finite(o%w_last + o%d_damp + o%d_links + o%d_contact + o%d_impact)
   end procedure energy_grid

   !> The energy terms at the committed state (u, v, a; ms, or the method's energies), on
   !> the energy grid (grid) its largest |balance| so far, and e_mech = KE + E_rec for the
   !> divergence test.
   module procedure energy_at
      real(dp) :: e_kin, e_links, e_cont, kc
      if (present(energies)) then
         e_kin = energies(1); e_links = energies(2); e_cont = energies(3)
      else
         e_kin = kinetic_energy(m, v, o%work)
         call recoverable_energy(m, ms, u, e_links, e_cont)
      end if
      kc = kinetic_correction(o, m, a)
      o%energy = energy_terms(o%e0, o%w_ext, e_kin, e_links, e_cont, o%e_links0, o%e_cont0, &
                              o%d_damp, o%d_links, o%d_contact, o%d_impact, kc, o%ke_corr0)
      if (grid) o%energy_balance_max = max(o%energy_balance_max, abs(o%energy(E_BALANCE)))
      e_mech = e_kin + e_links + e_cont
   end procedure energy_at

   !> The energy terms from the accumulated works (W, since t = 0) and recoverable energies:
   !> the dissipation of links (plasticity) and contacts is their work minus the change of
   !> their recoverable energy, so the balance is the work–energy identity
   !> KE0 + W_ext − KE − W_damp − W_links − W_contact − W_impact (≈ 0 to the method's accuracy).
   !> ke_corr, ke_corr0: a method's correction to ½vᵀMv in its conserved energy, now and at
   !> t = 0 (central difference; 0 for the others).
   pure function energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0) result(e)
      real(dp), intent(in) :: e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0
      real(dp) :: e(NENERGY)
      e = 0.0_dp
      e(E_KINETIC) = e_kin; e(E_RECOVERABLE) = e_links + e_cont; e(E_INPUT) = w_ext
      e(E_DAMPING) = d_damp
      e(E_PLASTIC) = d_links - (e_links - e_links0)
      e(E_CONTACT) = d_contact - (e_cont - e_cont0)
      e(E_INITIAL) = e0
      e(E_IMPACT) = d_impact
      e(E_BALANCE) = (e0 - ke_corr0) + w_ext - (e_kin - ke_corr) - e(E_RECOVERABLE) - e(E_DAMPING) &
                     - e(E_PLASTIC) - e(E_CONTACT) - e(E_IMPACT)
   end function energy_terms

   !> Divergence at time t, one rule for every integrator: a non-finite state or work, or
   !> the mechanical energy beyond divergence_factor·(e0 + Σ|ΔW_ext|), what the run was
   !> given, by more than ENERGY_FLOOR (docs/integrators.md "divergence detection").
   module procedure check_divergence
      stat = MARTELLO_OK
      if (.not. (ieee_is_finite(e_mech) .and. all_finite(u) .and. all_finite(v) .and. &
                 ieee_is_finite(o%w_ext + o%d_damp + o%d_links + o%d_contact + o%d_impact))) then
         call observer_fail_nonfinite(o, t, stat)
      else if (-(o%energy(E_CONTACT) + o%energy(E_IMPACT)) > CREATED_BOUND*(o%e0 + o%w_abs) &
               + ENERGY_FLOOR .and. o%e0 + o%w_abs > 0.0_dp) then
         ! a passive contact only takes energy out: the realised restitution exceeds 1
         write (o%message, '(a,a,a,a,a,a,a,a,a)') integrator_name(o%kind), &
            ' created energy at its contacts by t = ', sci(t, 5), ' s: ', &
            sci(-(o%energy(E_CONTACT) + o%energy(E_IMPACT)), 3), ' J, more than 1 % of the initial'// &
            ' energy + input work (', sci(o%e0 + o%w_abs, 3), ' J): a passive contact cannot'// &
            ' (restitution > 1); ', o%advice
         stat = MARTELLO_ERR_DIVERGED
         call observer_finish(o, t)
      else if (e_mech > o%divergence_factor*(o%e0 + o%w_abs) + ENERGY_FLOOR .and. &
               o%e0 + o%w_abs > 0.0_dp) then
         write (o%message, '(a,a,a,a,a,a,a,a,a)') integrator_name(o%kind), &
            ' diverged at t = ', sci(t, 5), ' s: mechanical energy ', sci(e_mech, 3), ' J exceeds ', &
            sci(o%divergence_factor*(o%e0 + o%w_abs), 3), &
            ' J (divergence_factor x (initial energy + input work)); ', o%advice
         stat = MARTELLO_ERR_DIVERGED
         call observer_finish(o, t)
      end if
   end procedure check_divergence

   !> Whether every entry of x is finite, in one pass with no branch per entry: x − x is 0
   !> for a finite x and NaN for ±∞ or NaN, and a NaN stays in a sum (two of them: half the
   !> additions in a chain). A non-finite entry raises no trap here that its making did not
   !> raise first (±∞ comes of an overflow).
   pure logical function all_finite(x)
      real(dp), intent(in) :: x(:)
      real(dp) :: s0, s1
      integer :: i, n
      n = size(x)
      s0 = 0.0_dp; s1 = 0.0_dp
      do i = 1, n - 1, 2
         s0 = s0 + (x(i) - x(i))
         s1 = s1 + (x(i + 1) - x(i + 1))
      end do
      if (mod(n, 2) == 1) s0 = s0 + (x(n) - x(n))
      all_finite = s0 + s1 == 0.0_dp
   end function all_finite
end submodule energy
