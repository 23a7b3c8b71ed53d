!> The generalized-α family as a stepper of the fixed-step strategy (docs/integrators.md):
!> one Newton kernel for Newmark (any β, γ; α_m = α_f = 0), HHT-α (α_m = 0, α_f = −α) and
!> Chung–Hulbert generalized-α (ρ∞). Residual with the forces interpolated between the old
!> and new states (Hilber et al. 1977; Chung & Hulbert 1993, eqs 3–5), consistent tangent,
!> and a residual-plus-increment convergence test. Every step is O(n·kd²): band assembly and
!> solve, workspaces allocated once per run.
module martello_generalized_alpha
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth
   use martello_element_rows, only: row_dot, row_add
   use martello_band_matrix
   use martello_assembly
   use martello_observer, only: observer_t, observer_work, observer_fail, free_side_crossing
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS, C_CHATTER
   use martello_contact_laws, only: contact_force, LAW_KELVIN, LAW_LINEAR, LAW_JANKOWSKI, P_CLIP, &
      P_STIFF, P_DAMPING
   use martello_links, only: LINK_BILINEAR, L_STIFF, L_YIELD, L_HARDENING
   use martello_integrator_settings
   use martello_stability, only: omega_max
   use martello_fixed_step, only: stepper_t, stepper_rest_start, stepper_fail, newmark_kinematics, &
      newmark_predictor, newmark_increment, contact_state, solve_free_mass
   implicit none
   private
   public :: generalized_alpha_t, generalized_alpha_coefficients

   !> The switches of a contact in an event-split step (first_switch), and the branch a
   !> contact is held on up to each (the left limit). SW_TURN: a Jankowski contact's switch
   !> between approach and restitution (δ̇ through 0: its damping term c δ̇ turns on or off,
   !> a kink of the force, no jump), solved on the whole law (δ̇ is 0 at its end to O(h³))
   integer, parameter :: SW_ONSET = 1, SW_SEPARATION = 2, SW_CUT = 3, SW_REENGAGE = 4, &
                         SW_CUT_SEPARATION = 5, SW_TURN = 6
   integer, parameter :: HELD(6) = [CONTACT_OPEN, CONTACT_ON, CONTACT_ON, CONTACT_CUT, CONTACT_CUT, &
                                    CONTACT_FREE]

   type, extends(stepper_t) :: generalized_alpha_t
      integer :: kd = 0, max_newton = 30
      real(dp) :: am = 0.0_dp, af = 0.0_dp, beta = 0.25_dp, gamma = 0.5_dp, cm = 0.0_dp, &
                  cv = 0.0_dp, mmax = 0.0_dp, tol_residual = 0.0_dp, tol_increment = 0.0_dp
      real(dp), allocatable :: fint(:), fint_n(:), fext(:), fext_n(:), res(:), du(:), work(:), &
                               ma(:), man(:)
      type(band_t) :: jac, mband, cjac
      !> J of the last converged iterate is assembled (and factored, or due): the next step
      !> starts from it
      logical :: tangent_valid = .false.
      !> The kept Newton matrix (docs/integrators.md, kept factors): J is assembled from the
      !> element tangents tan_link, tan_con (∂f/∂du, ∂f/∂du̇ of each element) at one iterate;
      !> an iterate whose tangents are the same numbers has the same J, so its factors serve
      !> again (a branch change of a piecewise-linear law, or any move of a nonlinear law's
      !> tangent, assembles and factors anew). jac_assembled: J holds an assembly of the current
      !> step length; jac_factored: its factors are in jac (made at the first solve after it).
      logical :: jac_assembled = .false., jac_factored = .false.
      real(dp), allocatable :: tan_link(:, :), tan_con(:, :), tan_link_trial(:, :), &
                               tan_con_trial(:, :), jdiag(:)
      !> event_split: a step is split at the located switches of the Kelvin, linear and
      !> Jankowski laws and bilinear links (docs/integrators.md, event-split steps); the step's
      !> start state is kept in us, vs, as
      logical :: event_split = .false.
      real(dp), allocatable :: us(:), vs(:), as(:), jump(:)
      !> the last step was split: its last stretch's a carries the lag of that stretch's
      !> length, not of h (consistent_newton)
      logical :: relag = .false.
   contains
      procedure :: init
      procedure :: step
   end type generalized_alpha_t

contains

   !> (α_m, α_f, β, γ) of the family member; α's weigh the old state.
   pure subroutine generalized_alpha_coefficients(s, am, af, beta, gamma)
      type(integrator_settings_t), intent(in) :: s
      real(dp), intent(out) :: am, af, beta, gamma
      select case (s%kind)
      case (INT_HHT)                 ! Hilber–Hughes–Taylor (1977)
         am = 0.0_dp; af = -s%alpha
         gamma = 0.5_dp - s%alpha; beta = 0.25_dp*(1.0_dp - s%alpha)**2
      case (INT_GENERALIZED_ALPHA)   ! Chung & Hulbert (1993), eq. 25
         am = (2.0_dp*s%rho_inf - 1.0_dp)/(s%rho_inf + 1.0_dp)
         af = s%rho_inf/(s%rho_inf + 1.0_dp)
         gamma = 0.5_dp - am + af; beta = 0.25_dp*(1.0_dp - am + af)**2
      case default                   ! Newmark (1959)
         am = 0.0_dp; af = 0.0_dp; beta = s%beta; gamma = s%gamma
      end select
   end subroutine generalized_alpha_coefficients

   !> The state at t = 0 with a = M⁻¹(f_ext − f_int) (M·1 carries gravity and ground motion).
   subroutine init(self, m, s, o, stat)
      class(generalized_alpha_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n
      character(len=256) :: msg
      n = m%n
      self%kd = model_bandwidth(m)
      allocate (self%fint(0:n), self%fint_n(0:n), self%fext(0:n), self%fext_n(0:n), &
                self%res(0:n), self%du(n), self%work(0:n), self%ma(0:n), self%man(0:n), stat=stat)
      if (stat /= 0) call out_of_memory('the force vectors of '//integrator_name(s%kind), &
                                        REAL_BYTES*(8*(n + 1.0_dp) + n), FIX_SMALLER_SCENE, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%jac, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%mband, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%cjac, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) then
         allocate (self%tan_link(2, m%nlink), self%tan_con(2, m%ncontact), self%jdiag(n), &
                   self%tan_link_trial(2, m%nlink), self%tan_con_trial(2, m%ncontact), stat=stat)
         if (stat /= 0) call out_of_memory('the element tangents of '//integrator_name(s%kind), &
                                           REAL_BYTES*(4*(m%nlink + m%ncontact) + n + 0.0_dp), &
                                           FIX_SMALLER_SCENE, stat, msg)
      end if
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      call stepper_rest_start(self, m, s, self%mband, self%fint, self%fext, o, stat)
      if (stat /= MARTELLO_OK) return
      self%advice = 'the step is past the stability limit'
      self%max_newton = s%max_newton
      self%tol_residual = s%tol_residual; self%tol_increment = s%tol_increment
      call generalized_alpha_coefficients(s, self%am, self%af, self%beta, self%gamma)
      self%cm = (1.0_dp - self%am)/(self%beta*self%h*self%h)
      self%mmax = max(maxval(m%mass), tiny(1.0_dp))
      self%cv = self%gamma/(self%beta*self%h)
      self%event_split = logical(s%event_split) .and. (any(m%con_law == LAW_KELVIN) .or. &
                                                        any(m%con_law == LAW_LINEAR) .or. &
                                                        any(m%con_law == LAW_JANKOWSKI) .or. &
                                                        any(m%link_kind == LINK_BILINEAR))
      if (self%event_split) then
         allocate (self%us(0:n), self%vs(0:n), self%as(0:n), self%jump(0:n), stat=stat)
         if (stat /= 0) then
            call out_of_memory('the event-split states of '//integrator_name(s%kind), &
                               REAL_BYTES*4*(n + 1.0_dp), FIX_SMALLER_SCENE, stat, msg)
            call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
            return
         end if
      end if
      if (s%kind == INT_NEWMARK .and. 2.0_dp*self%beta < self%gamma) &
         call newmark_stability(self%beta, self%gamma, self%h, logical(s%check_stability), stat)
   contains

      !> Newmark with 2β < γ is stable only for ω h ≤ 1/√(γ/2 − β) (undamped; Hughes 1987,
      !> "The finite element method", §9.1.3; docs/integrators.md): past it, with
      !> check_stability, the run is refused before its first step, as central difference's.
      subroutine newmark_stability(beta, gamma, h, check, stat)
         real(dp), intent(in) :: beta, gamma, h
         logical, intent(in) :: check
         integer, intent(inout) :: stat
         integer :: info
         character(len=512) :: msg
         real(dp) :: limit
         limit = 1.0_dp/sqrt(0.5_dp*gamma - beta)
         call omega_max(m, o%omega_max, info, stat, msg)
         if (stat /= MARTELLO_OK) then
            call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
            return
         end if
         if (info /= 0 .or. o%omega_max <= 0.0_dp) return
         o%dt_critical = limit/o%omega_max
         if (.not. check .or. h <= o%dt_critical) return
         write (msg, '(a,a,a,a,a,a,a,a,a,a,a)') 'newmark with beta = ', sci(beta, 3), &
            ' < gamma/2 (gamma = ', sci(gamma, 3), ') is unstable: dt = ', sci(h, 5), &
            ' s exceeds dt_crit = 1/(omega_max sqrt(gamma/2 - beta)) = ', sci(o%dt_critical, 5), &
            ' s (omega_max = ', sci(o%omega_max, 4), ' rad/s, penalty stiffness included); reduce dt or'// &
            ' take beta >= gamma/2'
         call observer_fail(o, MARTELLO_ERR_UNSTABLE, 0.0_dp, msg, stat)
      end subroutine newmark_stability
   end subroutine init

   !> One Newton-solved step, its trapezoidal works handed to the observer.
   subroutine step(self, m, t, o, stat)
      class(generalized_alpha_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      real(dp) :: rnorm, incr, fscale, uscale, fmag, fext_mag, wd, wl, wc, h
      real(dp) :: t_a      !< event-split steps: the start of the stretch being solved
      integer :: turned    !< event-split steps: a link unloaded at the stretch's start
      integer :: turned_con  !< event-split steps: a Jankowski contact turned at the stretch's start
      integer :: n
      logical :: ok, converged
      character(len=256) :: msg

      stat = MARTELLO_OK
      n = self%n; h = self%h
      self%fint_n = self%fint; self%fext_n = self%fext
      call mass_times(m, self%an, self%man)
      call external_forces(m, self%mrow, t, self%fext)
      fext_mag = maxval(abs(self%fext))
      if (self%relag) then
         self%relag = .false.
         call consistent_newton(converged)
      else
         call newton_step(converged)
      end if
      if (.not. converged) return
      if (self%event_split) then
         if (split_step()) return
      end if
      ! energy balance: trapezoidal work of every force over the step (elements in commit)
      call mech_commit(m, self%ms, self%u, wd, wl, wc)
      call observer_work(o, damping=wd, links=wl, contact=wc)
      call observer_work(o, external=external_work(m, self%fext_n, self%fext, self%un, self%u))
      call contact_state(self, m)

   contains

      !> The event-split step (docs/integrators.md, event-split steps). The switches of the
      !> piecewise-smooth laws — a Kelvin contact's onset and separation (its force jumps by
      !> cδ̇), its cut-off and re-engagement when clipped, a linear contact's onset and
      !> separation, a bilinear link's yield and unloading (the slope of the force jumps) —
      !> are looked for in the stretch just solved (first_switch). At the first, τ from the
      !> stretch's start, the stretch is re-taken as a sub-step [t_a, t_a + τ] with the laws on
      !> the start's branches (the left limit: a contact held on its branch; a bilinear link
      !> reaches its yield line at the end to O(h³) under the return map, and is put on it),
      !> the contact force takes its new branch's value at the boundary (boundary_jump: the
      !> right limit), and the rest [t_a + τ, t] is solved and looked at again, up to
      !> MAX_SPLITS switches a step. Each sub-step then integrates a smooth force, whatever its
      !> length: the state moves by Newton increments (newmark_increment), so a sub-step τ ≪ h
      !> carries no rounding of u into a. A contact's switch that the clock does not tell from
      !> a stretch end (switch_time) is on that end (the jump at the start, or at the end after
      !> a sub-step over the whole stretch); a link's is already on a boundary. False: no
      !> switch, the step stands as solved.
      logical function split_step() result(split)
         integer, parameter :: MAX_SPLITS = 8
         integer :: k, first, kind, j
         integer :: waits(m%ncontact)      !< the switch each contact awaits from the start
         integer :: branch(m%ncontact)     !< the branches as they were (the whole laws)
         logical :: on_start(m%ncontact)   !< in contact at the sub-step's start
         real(dp) :: tau, h_full, h_left
         logical :: pending
         split = .false.
         pending = .true.                ! the solved stretch is not committed
         h_full = h
         t_a = self%t0                   ! the stretch [t_a, t] of length h
         turned = 0; turned_con = 0
         do k = 1, MAX_SPLITS
            call first_switch(first, tau, kind)
            if (first == 0) exit
            if (.not. split) then
               self%us = self%un; self%vs = self%vn; self%as = self%an
               split = .true.
            end if
            if (tau == 0.0_dp) then
               ! a contact's switch at the stretch's start: the jump there, the stretch again
               self%u = self%un; self%v = self%vn; self%a = self%an; self%fint = self%fint_n
               if (.not. boundary_jump(first, kind)) return
               self%an = self%a; self%fint_n = self%fint
               call solve_stretch(t_a, h)
               if (.not. converged) return
               cycle
            end if
            ! the sub-step to the switch: no law switches before it, so every contact is held
            ! on its start's branch up to its end (the left limit), whatever the sign of its
            ! switch there — the first's is 0 to the step's O(h³), and another's that falls at
            ! the same instant (P7's symmetric chain: four contacts close at once) is the
            ! first's to its own O(h³): left to the whole law, it switched inside the
            ! sub-step or not as the rounding fell, its jump inside a step (an O(h) error)
            self%ms%forced_off = .false.
            branch = self%ms%con_branch; on_start = self%ms%con_on
            do j = 1, m%ncontact
               waits(j) = awaited_switch(j)
               if (waits(j) /= 0) self%ms%con_branch(j) = HELD(waits(j))
            end do
            if (first > 0) self%ms%con_branch(first) = HELD(kind)
            h_left = h
            call set_step(tau)
            call external_forces(m, self%mrow, t_a + tau, self%fext)
            fext_mag = maxval(abs(self%fext))
            call consistent_newton(converged)
            self%ms%con_branch = branch
            if (.not. converged) return
            call commit_works()
            pending = .false.
            if (first > 0) then
               if (.not. boundary_jump(first, kind)) return
            end if
            ! the others held past their switch in the sub-step: their jumps at the boundary
            ! too; those not past it are still on their branch (mech_commit's δ > 0 is the
            ! rounding of a switch just taken at the sub-step's start)
            do j = 1, m%ncontact
               if (j == first .or. waits(j) == 0) cycle
               if (past_switch(j, waits(j))) then
                  if (.not. boundary_jump(j, waits(j))) return
               else
                  self%ms%con_on(j) = on_start(j)
               end if
            end do
            if (first < 0 .and. kind /= 0) then
               ! a yield: the boundary is on the yield line (the sub-step's end is on it to
               ! O(h³), either side): the committed force is put on it, so the rest of the
               ! step starts on the line, not an O(h³) short of it
               associate (j => -first)
                  self%ms%link_fc(j) = m%link_par(L_HARDENING, j)*m%link_par(L_STIFF, j)* &
                                       self%ms%link_u(j) + kind*(1.0_dp - &
                                       m%link_par(L_HARDENING, j))*m%link_par(L_YIELD, j)
               end associate
            end if
            ! an unloading: the link has turned at the boundary (located to O(h²) in time, its
            ! du̇ may still point outward there): the rest of the step starts it elastic
            turned = 0; turned_con = 0
            if (first < 0 .and. kind == 0) turned = -first
            ! a Jankowski contact that turned at the boundary (located from the start's rates:
            ! its δ̇ may still have the old sign there, within the step's O(h²)): the rest of
            ! the step does not look for that turn again (a sub-step of a few ulps of the step
            ! would follow, whose algorithmic acceleration carries the rounding of u over τ²)
            if (first > 0 .and. kind == SW_TURN) turned_con = first
            if (tau >= h_left) exit                 ! the switch is on the step's end
            ! the rest of the step, from the boundary
            self%un = self%u; self%vn = self%v; self%an = self%a
            self%fint_n = self%fint; self%fext_n = self%fext
            call solve_stretch(t_a + tau, h_left - tau)
            if (.not. converged) return
            pending = .true.
         end do
         if (.not. split) return
         if (pending) call commit_works()
         ! the step as the strategy and the observer know it: [t0, t]
         self%un = self%us; self%vn = self%vs; self%an = self%as
         call set_step(h_full)
         call contact_state(self, m)
         self%relag = .true.
      end function split_step

      !> Solve the stretch [ta, t] of length hh from the state (un, vn, an) (uncommitted)
      subroutine solve_stretch(ta, hh)
         real(dp), intent(in) :: ta, hh
         t_a = ta
         call mass_times(m, self%an, self%man)
         call set_step(hh)
         call external_forces(m, self%mrow, t, self%fext)
         fext_mag = maxval(abs(self%fext))
         self%ms%forced_off = .false.
         call consistent_newton(converged)
      end subroutine solve_stretch

      !> Newton on a stretch that does not continue one of its own length on its branch (an
      !> event-split sub-step, the rest of a split step, the step after one). An α-method's a
      !> is the acceleration at t + c·h, c = α_m − α_f, h the stretch's length (Erlicher et al.
      !> 2002; docs/integrators.md, event-split steps): the start state carries the lag of
      !> another length, or of the branch before a switch — an O(h) error of a, O(h²) of v at
      !> every boundary, with a constant set by where the switch falls in the step. So the
      !> stretch is solved once, its start's a set to ẍ_s + c(ẍ_e − ẍ_s), ẍ = M⁻¹(f_ext − f_int)
      !> at its two ends on its branch (the right limit at the start), and solved again.
      !> Newmark (c = 0): one solve, its a is ẍ already.
      subroutine consistent_newton(converged)
         logical, intent(out) :: converged
         real(dp) :: c
         c = self%am - self%af
         call newton_step(converged)
         if (c == 0.0_dp .or. .not. converged) return
         self%work = self%fext - self%fint
         call solve_free_mass(m, self%fixed_nodes, self%mband, self%work, ok)
         self%jump = self%fext_n - self%fint_n
         if (ok) call solve_free_mass(m, self%fixed_nodes, self%mband, self%jump, ok)
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 2_i8
         if (.not. ok) then
            converged = .false.
            call stepper_fail(o, MARTELLO_ERR_SINGULAR, t, 'singular mass at an event-split boundary', stat)
            return
         end if
         self%an = self%jump + c*(self%work - self%jump)
         call mass_times(m, self%an, self%man)
         call newton_step(converged)
      end subroutine consistent_newton

      !> The first switch of the stretch just solved, from its start (un, vn, an; the laws
      !> committed there) to its solved end (u, v), on the branches committed at the start:
      !> first = j > 0 for contact j, with kind its switch (SW_ONSET from open, SW_SEPARATION
      !> from closed, a clipped Kelvin's SW_CUT where kδ + cδ̇ turns tensile, SW_REENGAGE
      !> where it turns compressive again while δ > 0 and SW_CUT_SEPARATION where it
      !> separates from its cut-off state, with F = 0 on both sides), −j for bilinear link j, with
      !> kind = ±1 for a yield onto the upper or lower line and 0 for unloading; 0 if none.
      !> Each switch g (> 0: the branch is left) is followed on the start's quadratic
      !> g + ġτ + ½g̈τ² (without the jerk where g holds a rate: unloading −du̇, the Kelvin
      !> force kδ + cδ̇), and a sign change of the solved end is a switch where the quadratic
      !> has none (chatter rule, or the return map past its surface). tau: from the stretch's
      !> start (0 and h: a contact's switch on that end, switch_time).
      subroutine first_switch(first, tau, kind)
         integer, intent(out) :: first, kind
         real(dp), intent(out) :: tau
         integer :: j, sw, kj
         real(dp) :: sg, d0, r0, q0, d1, r1, tj, k, rho, r, fp, c0, round, kap
         first = 0; tau = huge(1.0_dp); kind = 0
         do j = 1, m%ncontact
            if (.not. self%ms%is_penalty(j) .or. .not. kinked_law(j)) cycle
            d0 = row_dot(m%con, j, self%un) - m%con_gap(j); d1 = row_dot(m%con, j, self%u) - m%con_gap(j)
            r0 = row_dot(m%con, j, self%vn); r1 = row_dot(m%con, j, self%v)
            q0 = row_dot(m%con, j, self%an)
            if (.not. self%ms%con_on(j)) then
               kj = SW_ONSET; sg = 1.0_dp                  ! g = δ
            else if (m%con_law(j) == LAW_JANKOWSKI) then
               ! its separation (F ~ δ^(3/2): C¹) and its turn, δ̇ through 0 (g = ∓δ̇ from the
               ! start's sign; no jerk: O(h²) in time, a C¹ kink whose location error costs
               ! its square), a boundary without a jump
               if (r0 /= 0.0_dp .and. j /= turned_con) then
                  sg = sign(1.0_dp, r0)
                  tj = switch_time(-sg*r0, -sg*q0, 0.0_dp, -sg*r1, .false.)
                  if (tj < tau) then
                     tau = tj; first = j; kind = SW_TURN
                  end if
               end if
               kj = SW_SEPARATION; sg = -1.0_dp
            else if (.not. clipped(j)) then
               kj = SW_SEPARATION; sg = -1.0_dp            ! g = −δ
            else
               ! cut off (no force while δ > 0): it separates at δ = 0 with F = 0 on both sides,
               ! a switch without a jump that makes a later closing an onset
               if (.not. (self%ms%con_f(j) > 0.0_dp)) then
                  tj = switch_time(-d0, -r0, -q0, -d1, .true.)
                  if (tj < tau) then
                     tau = tj; first = j; kind = SW_CUT_SEPARATION
                  end if
               end if
               ! the clipped Kelvin force over k, δ + κδ̇: −(it) while it pushes, +(it) while cut
               kap = m%con_par(P_DAMPING, j)/m%con_par(P_STIFF, j)
               kj = merge(SW_CUT, SW_REENGAGE, self%ms%con_f(j) > 0.0_dp)
               sg = merge(-1.0_dp, 1.0_dp, kj == SW_CUT)
               d0 = d0 + kap*r0; d1 = d1 + kap*r1; r0 = r0 + kap*q0
            end if
            tj = switch_time(sg*d0, sg*r0, sg*q0, sg*d1, .true.)
            if (tj < tau) then
               tau = tj; first = j; kind = kj
            end if
         end do
         do j = 1, m%nlink
            if (m%link_kind(j) /= LINK_BILINEAR) cycle
            k = m%link_par(L_STIFF, j); rho = m%link_par(L_HARDENING, j)
            if (rho >= 1.0_dp) cycle
            r = (1.0_dp - rho)*m%link_par(L_YIELD, j)
            r0 = row_dot(m%lnk, j, self%vn); q0 = row_dot(m%lnk, j, self%an)
            ! the branch committed: on a yield line (to the rounding of the return map's clamp)
            ! while loading outward, else in the elastic band
            fp = self%ms%link_fc(j) - rho*k*self%ms%link_u(j)
            round = 64.0_dp*epsilon(1.0_dp)*(abs(self%ms%link_fc(j)) + rho*k*abs(self%ms%link_u(j)) + r)
            sw = 0
            if (fp >= r - round .and. r0 > 0.0_dp) sw = 1
            if (fp <= -(r - round) .and. r0 < 0.0_dp) sw = -1
            if (j == turned) sw = 0
            if (sw /= 0) then
               ! unloading: g = ∓du̇
               tj = switch_time(-sw*r0, -sw*q0, 0.0_dp, -sw*row_dot(m%lnk, j, self%v), .false.)
               if (tj < tau) then
                  tau = tj; first = -j; kind = 0
               end if
               cycle
            end if
            ! yield: g = ±(f_n + k(du − u_n) − ρk du) − (1 − ρ)F_y, in force units
            c0 = self%ms%link_fc(j) - k*self%ms%link_u(j)
            d0 = row_dot(m%lnk, j, self%un); d1 = row_dot(m%lnk, j, self%u)
            do sw = 1, -1, -2
               tj = switch_time(sw*(c0 + (1.0_dp - rho)*k*d0) - r, sw*(1.0_dp - rho)*k*r0, &
                                sw*(1.0_dp - rho)*k*q0, sw*(c0 + (1.0_dp - rho)*k*d1) - r, .false.)
               if (tj < tau) then
                  tau = tj; first = -j; kind = sw
               end if
            end do
         end do
      end subroutine first_switch

      !> When g (≤ 0 at the stretch's start: a value past 0 there is a switch just taken, to
      !> the O(h³) of its location) first becomes > 0 in the stretch [0, h]: on the start's
      !> quadratic g0 + g1 τ + ½g2 τ², or at the crossing of the solved end g_end > 0 located
      !> on the free side; huge if never. A switch whose time the clock does not tell from an
      !> end — x + τ = x or x + (h − τ) = x in floating point, x = max(t_a, h), the time and
      !> the stretch's length — is at that end: ends, put on it (0 or h); otherwise no switch
      !> of the stretch (huge). No sub-step is thus shorter than half an ulp of h (its
      !> 1/(βτ²) stays finite), and no switch is moved by more than the clock's rounding.
      real(dp) function switch_time(g0, g1, g2, g_end, ends) result(tau)
         real(dp), intent(in) :: g0, g1, g2, g_end
         logical, intent(in) :: ends
         real(dp) :: g, x
         g = min(g0, 0.0_dp)
         if (g == 0.0_dp .and. (g1 > 0.0_dp .or. (g1 == 0.0_dp .and. g2 > 0.0_dp))) then
            tau = 0.0_dp
         else
            tau = first_root(g, g1, g2)
            if (tau >= h) then
               tau = huge(1.0_dp)
               if (g_end > 0.0_dp) tau = free_side_crossing(g, g1, g2, 0.0_dp, h)
            end if
         end if
         if (tau > h) return
         x = max(t_a, h)
         if (.not. (x + tau > x)) then
            tau = merge(0.0_dp, huge(1.0_dp), ends)
         else if (.not. (x + (h - tau) > x)) then
            tau = merge(h, huge(1.0_dp), ends)
         end if
      end function switch_time

      !> The force of contact j just past its onset at the current end state (δ ≥ 0 to the
      !> step's accuracy: Kelvin kδ + cδ̇, clipped as the law says; linear kδ, ≈ 0).
      real(dp) function onset_force(j) result(fplus)
         integer, intent(in) :: j
         real(dp) :: d, r, dfd, dfv
         d = row_dot(m%con, j, self%u) - m%con_gap(j)
         r = row_dot(m%con, j, self%v)
         call contact_force(m%con_law(j), m%con_par(1, j), m%con_mstar(j), max(d, tiny(1.0_dp)), &
                            r, r, fplus, dfd, dfv)
      end function onset_force

      !> The contact laws whose force is not smooth at δ = 0: Kelvin (it jumps by cδ̇), linear
      !> (its slope jumps by k) and Jankowski (its damping c δ^(1/4) δ̇ rises as δ^(1/4), and
      !> switches off and on with the sign of δ̇); the Hertz and Hunt–Crossley family rise as
      !> δ^n, n > 1, smoothly enough for the trapezoidal rule's second order.
      pure logical function kinked_law(j)
         integer, intent(in) :: j
         kinked_law = m%con_law(j) == LAW_KELVIN .or. m%con_law(j) == LAW_LINEAR .or. &
                      m%con_law(j) == LAW_JANKOWSKI
      end function kinked_law

      pure logical function clipped(j)
         integer, intent(in) :: j
         clipped = m%con_law(j) == LAW_KELVIN .and. m%con_par(P_CLIP, j) > 0.5_dp
      end function clipped

      !> The switch contact j awaits from the committed state (first_switch's kinds; its
      !> branch up to it is HELD of it): SW_ONSET while open, SW_SEPARATION while in contact,
      !> a clipped Kelvin's SW_CUT while it pushes and SW_REENGAGE while cut off; 0 for a
      !> contact without a kink to hold (Jankowski, whose force is C¹ at δ = 0 and whose
      !> turn is a kink of its damping alone; the smooth laws; the other schemes).
      integer function awaited_switch(j) result(kj)
         integer, intent(in) :: j
         kj = 0
         if (.not. self%ms%is_penalty(j) .or. .not. kinked_law(j)) return
         if (.not. self%ms%con_on(j)) then
            kj = SW_ONSET
         else if (m%con_law(j) == LAW_JANKOWSKI) then
            kj = 0
         else if (.not. clipped(j)) then
            kj = SW_SEPARATION
         else
            kj = merge(SW_CUT, SW_REENGAGE, self%ms%con_f(j) > 0.0_dp)
         end if
      end function awaited_switch

      !> Contact j, held on its branch over the sub-step from (un, vn) to (u, v), crossed its
      !> switch kj in it: its switch function g went from ≤ 0 at the start to > 0 at the end
      !> (g = δ for an onset, −δ for a separation — in contact while δ > 0, as mech_commit
      !> says —, ∓(δ + κδ̇), κ = c/k, for a clipped Kelvin's cut-off and re-engagement, this
      !> one only while δ > 0). A g already > 0 at the start is a switch taken there, whose
      !> location leaves it a rounding past 0, not one to take again.
      logical function past_switch(j, kj) result(past)
         integer, intent(in) :: j, kj
         real(dp) :: d0, d1, kappa, k0, k1
         d0 = row_dot(m%con, j, self%un) - m%con_gap(j)
         d1 = row_dot(m%con, j, self%u) - m%con_gap(j)
         select case (kj)
         case (SW_ONSET)
            past = .not. d0 > 0.0_dp .and. d1 > 0.0_dp
         case (SW_SEPARATION)
            past = d0 > 0.0_dp .and. .not. d1 > 0.0_dp
         case default
            kappa = m%con_par(P_DAMPING, j)/m%con_par(P_STIFF, j)
            k0 = d0 + kappa*row_dot(m%con, j, self%vn)
            k1 = d1 + kappa*row_dot(m%con, j, self%v)
            if (kj == SW_CUT) then
               past = .not. k0 < 0.0_dp .and. k1 < 0.0_dp
            else
               past = .not. k0 > 0.0_dp .and. k1 > 0.0_dp .and. d1 > 0.0_dp
            end if
         end select
      end function past_switch

      !> Contact j takes its new branch at the current end state, a boundary of the smooth
      !> stretches (switch kind of first_switch): the force of that branch (an onset or a
      !> re-engagement: the law's; a separation or a cut-off: 0) in the internal force, the
      !> committed contact force and the acceleration (M Δa = −ΔF), and con_on (in contact,
      !> δ > 0, for the phases) but for the separations. False (with the failure handed over)
      !> if M is singular.
      logical function boundary_jump(j, kind) result(ok)
         integer, intent(in) :: j, kind
         real(dp) :: fplus
         ok = .true.
         if (kind == SW_TURN) return          ! a kink: the force is continuous there
         fplus = 0.0_dp
         if (kind == SW_ONSET .or. kind == SW_REENGAGE) fplus = max(onset_force(j), 0.0_dp)
         self%ms%con_on(j) = kind /= SW_SEPARATION .and. kind /= SW_CUT_SEPARATION
         self%jump = 0.0_dp
         call row_add(m%con, j, -(fplus - self%ms%con_f(j)), self%jump)   ! −g ΔF on the nodes
         self%fint = self%fint - self%jump
         self%fint(0) = 0.0_dp
         self%ms%con_f(j) = fplus
         call solve_free_mass(m, self%fixed_nodes, self%mband, self%jump, ok)
         if (.not. ok) then
            call stepper_fail(o, MARTELLO_ERR_SINGULAR, t, 'singular mass at an event-split boundary', stat)
            return
         end if
         self%a = self%a + self%jump
         self%tangent_valid = .false.
      end function boundary_jump

      !> The first root τ in (0, h) of d + rτ + ½qτ² (h if none)
      real(dp) function first_root(d, r, q) result(tau)
         real(dp), intent(in) :: d, r, q
         real(dp) :: disc, w, t1, t2
         tau = h
         if (q == 0.0_dp) then
            if (r /= 0.0_dp) t1 = -d/r
            if (r /= 0.0_dp .and. t1 > 0.0_dp .and. t1 < h) tau = t1
            return
         end if
         disc = r*r - 2.0_dp*q*d
         if (disc < 0.0_dp) return
         w = -(r + sign(sqrt(disc), r))         ! the cancellation-free pair: w/q and 2d/w
         t1 = w/q
         t2 = h
         if (w /= 0.0_dp) t2 = 2.0_dp*d/w
         if (t1 > 0.0_dp .and. t1 < tau) tau = t1
         if (t2 > 0.0_dp .and. t2 < tau) tau = t2
      end function first_root

      !> The step length hh in the Newmark coefficients; the next Newton starts from the predictor
      subroutine set_step(hh)
         real(dp), intent(in) :: hh
         h = hh; self%h = hh
         self%cm = (1.0_dp - self%am)/(self%beta*hh*hh)
         self%cv = self%gamma/(self%beta*hh)
         self%tangent_valid = .false.
         self%jac_assembled = .false.; self%jac_factored = .false.
      end subroutine set_step

      !> Commit a (sub-)step: its trapezoidal works to the observer
      subroutine commit_works()
         call mech_commit(m, self%ms, self%u, wd, wl, wc)
         call observer_work(o, damping=wd, links=wl, contact=wc)
         call observer_work(o, external=external_work(m, self%fext_n, self%fext, self%un, self%u))
      end subroutine commit_works

      !> Newton on the step. A law whose force jumps at δ = 0 (Kelvin: cδ̇ at first touch and
      !> at separation) can leave the step without any root: the iterates then flip the
      !> contact on and off. Chatter rule: a contact that flips in three iterations of one
      !> step is held open (F = 0) for this step and Newton restarts; the onset is thus
      !> delayed, or the separation advanced, by at most one step (O(h), counted in the
      !> contact_chatter_resolutions counter).
      subroutine newton_step(converged)
         logical, intent(out) :: converged
         integer :: restart
         integer :: flips(m%ncontact)
         logical :: was_on(m%ncontact)
         converged = .false.
         do restart = 0, 1
            flips = 0; was_on = self%ms%con_on
            if (restart == 0 .and. self%tangent_valid) then
               ! First iterate from the committed state with the tangent assembled there at
               ! the end of the last step: no element loop is needed for it, so a step whose
               ! laws stay on one branch costs a single evaluation.
               call linearised_first_iterate(ok)
               if (.not. ok) then
                  call stepper_fail(o, MARTELLO_ERR_SINGULAR, t, 'singular effective stiffness in the Newton step', stat)
                  return
               end if
               call newton_iterations(converged, flips, was_on, 1)
            else
               ! predictor: constant acceleration
               call newmark_predictor(self)
               call newton_iterations(converged, flips, was_on, 0)
            end if
            self%tangent_valid = converged
            if (converged .or. stat /= MARTELLO_OK) return
            if (.not. any(flips >= 3)) exit
            self%ms%forced_off = self%ms%forced_off .or. flips >= 3
            o%counters(C_CHATTER) = o%counters(C_CHATTER) + 1_i8
         end do
         if (.not. converged) then
            write (msg, '(a,a,a,i0,a,a,a,a,a)') 'Newton did not converge at t = ', sci(t, 5), &
               ' s after ', self%max_newton, ' iterations (residual ', sci(rnorm/fscale, 2), &
               ' of the force scale, tolerance ', sci(self%tol_residual, 2), '); reduce dt'
            call observer_fail(o, MARTELLO_ERR_NOT_CONVERGED, t, msg, stat)
         end if
      end subroutine newton_step

      !> u = u_n + Δu with J Δu = −r(u_n), where r(u_n) uses the committed internal force and
      !> the damping tangent C of the last evaluation for the velocity change (exact for
      !> linear dampers), solved with J's kept factors.
      subroutine linearised_first_iterate(ok)
         logical, intent(out) :: ok
         associate (u => self%u, v => self%v, a => self%a, un => self%un, vn => self%vn, &
                    fint_n => self%fint_n, fext => self%fext, fext_n => self%fext_n, &
                    res => self%res, du => self%du, work => self%work, ma => self%ma, &
                    man => self%man, am => self%am, af => self%af)
            u = un
            call newmark_kinematics(self, self%beta, self%gamma)
            work(1:n) = v(1:n) - vn(1:n)
            call band_matvec(self%cjac, work(1:n), res(1:n))   ! C_t Δv
            res(0) = 0.0_dp
            call mass_times(m, a, ma)
            res = (1.0_dp - am)*ma + am*man + (1.0_dp - af)*(fint_n + res) + af*fint_n &
                  - (1.0_dp - af)*fext - af*fext_n
            res(self%fixed_nodes) = 0.0_dp
            du = -res(1:n)
            call solve_kept(du, ok)
            o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
            call newmark_increment(self, du, self%beta, self%gamma)
         end associate
      end subroutine linearised_first_iterate

      !> Residual of the step at the current u, the effective stiffness
      !> J = c_m M + (1−α_f)(K_t + c_v C_t) with fixed rows pinned, min_i J_ii, and the
      !> damping tangent C_t (kept for the next step's first iterate).
      subroutine evaluate(want_jac)
         logical, intent(in) :: want_jac
         integer :: i
         associate (u => self%u, v => self%v, a => self%a, fint => self%fint, &
                    fint_n => self%fint_n, fext => self%fext, fext_n => self%fext_n, &
                    res => self%res, ma => self%ma, man => self%man, jac => self%jac, &
                    cjac => self%cjac, am => self%am, af => self%af, kd => self%kd)
            if (want_jac) then
               call internal_forces(m, self%ms, u, v, fint, link_tan=self%tan_link_trial, &
                                    con_tan=self%tan_con_trial)
               if (.not. (self%jac_assembled .and. all(self%tan_link_trial == self%tan_link) .and. &
                          all(self%tan_con_trial == self%tan_con))) then
                  ! a tangent moved: J anew on this iterate's tangents, factored when solved
                  jac%ab = 0.0_dp; cjac%ab = 0.0_dp
                  call internal_forces(m, self%ms, u, v, fint, jac%ab, 1.0_dp - af, &
                                       (1.0_dp - af)*self%cv, cjac%ab)
                  call assemble_mass(m, self%cm, jac)
                  o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
                  do i = 1, size(self%fixed_nodes)
                     call band_pin(jac, self%fixed_nodes(i))
                  end do
                  self%jdiag = jac%ab(2*kd + 1, :)
                  self%tan_link = self%tan_link_trial; self%tan_con = self%tan_con_trial
                  self%jac_assembled = .true.; self%jac_factored = .false.
               end if
            else
               call internal_forces(m, self%ms, u, v, fint)
            end if
            o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
            call mass_times(m, a, ma)
            ! residual and the magnitudes for the convergence test, in one pass
            rnorm = 0.0_dp; fmag = fext_mag
            do i = 1, n
               res(i) = (1.0_dp - am)*ma(i) + am*man(i) + (1.0_dp - af)*fint(i) + af*fint_n(i) &
                        - (1.0_dp - af)*fext(i) - af*fext_n(i)
               fmag = max(fmag, abs(fint(i)), abs(ma(i)))
            end do
            res(0) = 0.0_dp
            res(self%fixed_nodes) = 0.0_dp
            rnorm = maxval(abs(res(1:n)))
            ! the next Newton increment, estimated node by node as |r_i|/J_ii (exact for a
            ! diagonal J, within a factor 2 for the diagonally dominant J of a chain): a light
            ! node next to a heavy one is judged by its own stiffness, not the global minimum
            incr = 0.0_dp
            if (want_jac) then
               do i = 1, n
                  if (res(i) /= 0.0_dp) incr = max(incr, abs(res(i))/abs(self%jdiag(i)))
               end do
            end if
         end associate
      end subroutine evaluate

      !> J x = rhs in place with J's kept factors, factoring J first if it was assembled since
      !> (counted in factorizations); ok = .false. if J is singular.
      subroutine solve_kept(x, ok)
         real(dp), intent(inout) :: x(:)
         logical, intent(out) :: ok
         if (.not. self%jac_factored) then
            call band_factor(self%jac, ok)
            o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
            if (.not. ok) then
               self%jac_assembled = .false.
               return
            end if
            self%jac_factored = .true.
         end if
         ok = .true.
         call band_solve_factored(self%jac, x)
      end subroutine solve_kept

      subroutine newton_iterations(converged, flips, was_on, first)
         logical, intent(out) :: converged
         integer, intent(inout) :: flips(:)
         logical, intent(inout) :: was_on(:)
         integer, intent(in) :: first
         integer :: i, it
         logical :: on
         converged = .false.
         associate (u => self%u, un => self%un, vn => self%vn, an => self%an, du => self%du, &
                    res => self%res)
            uscale = tiny(1.0_dp)
            do i = 1, n
               uscale = max(uscale, abs(un(i)), h*abs(vn(i)), h*h*abs(an(i)))
            end do
            do it = first, self%max_newton
               ! J at every iterate's tangents (kept while they do not move): the converged one
               ! serves the next step
               call evaluate(.true.)
               do i = 1, m%ncontact
                  on = self%ms%con_pen_trial(i) > 0.0_dp .and. .not. self%ms%forced_off(i)
                  if (on .neqv. was_on(i)) flips(i) = flips(i) + 1
                  was_on(i) = on
               end do
               ! The inertia term cm·M·u is evaluated with rounding error ~ε·cm·m·|u|, which can
               ! exceed the physical forces by far (small h, free flight): it floors the scale.
               fscale = max(fmag, 64.0_dp*epsilon(1.0_dp)/self%tol_residual*self%cm*self%mmax*uscale, &
                            tiny(1.0_dp))
               ! residual test, and the increment the next iteration would make, both small
               if (it == 1) uscale = max(uscale, maxval(abs(u)))
               if (it > 0 .and. rnorm <= self%tol_residual*fscale .and. &
                   incr <= self%tol_increment*uscale) then
                  converged = .true.
                  exit
               end if
               if (it == self%max_newton) exit
               du = -res(1:n)
               call solve_kept(du, ok)
               o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
               if (.not. ok) then
                  call stepper_fail(o, MARTELLO_ERR_SINGULAR, t, 'singular effective stiffness in the Newton step', stat)
                  return
               end if
               if (it >= 2) then
                  call line_search(flips, was_on)
               else
                  call newmark_increment(self, du, self%beta, self%gamma)
               end if
            end do
         end associate
      end subroutine newton_iterations

      !> Backtracking on ‖r‖∞ once plain Newton has taken two steps without converging: laws
      !> whose tangent is unbounded at first touch (Jankowski: ∂F/∂δ ~ δ^{−3/4}) or that switch
      !> branch inside a step make full steps overshoot; halving restores a decrease.
      !> A full step rejected while it would close or open a contact counts as a flip of it
      !> (the chatter rule): where the step's solution sits on a jump of the force (a Kelvin
      !> contact whose δ = 0 falls on the step's end: the force cδ̇ on one side of the
      !> rounding of δ, none on the other), halving approaches the jump from one side without
      !> ever flipping, and Newton would stall there instead of holding the contact open.
      subroutine line_search(flips, was_on)
         integer, intent(inout) :: flips(:)
         logical, intent(in) :: was_on(:)
         real(dp) :: lam, r0, taken
         integer :: k, i
         r0 = rnorm
         lam = 1.0_dp; taken = 0.0_dp
         do k = 1, 12
            ! the trial lam·Δu from the iterate, by the increment from the last trial: u, v
            ! and a move together (newmark_increment)
            self%work(1:n) = (lam - taken)*self%du
            call newmark_increment(self, self%work(1:n), self%beta, self%gamma)
            taken = lam
            call evaluate(.false.)       ! the residual alone
            if (rnorm < r0) return
            if (k == 1) then
               do i = 1, m%ncontact
                  if ((self%ms%con_pen_trial(i) > 0.0_dp .and. .not. self%ms%forced_off(i)) &
                      .neqv. was_on(i)) flips(i) = flips(i) + 1
               end do
            end if
            lam = 0.5_dp*lam
         end do
      end subroutine line_search
   end subroutine step
end module martello_generalized_alpha
