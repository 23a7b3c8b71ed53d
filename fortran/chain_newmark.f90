!> The fused chain step (docs/run-layer.md "The fused chain step"): Newmark (β, γ) on a chain,
!> a scene whose effective stiffness is tridiagonal (every link and contact couples nodes i
!> and i ± 1, or a node and ground; lumped masses) and whose laws are piecewise linear
!> (springs, bars, dashpots, bilinear springs; linear and Kelvin penalty contacts).
!>
!> Newton's method on the step equations, as the general path (martello_generalized_alpha)
!> does, but on such a scene one Newton step from a state is exact as long as no law changes
!> branch between the linearisation and the new iterate. A step is one forward sweep (the
!> residual at u = uₙ linearised about the committed state, forward substitution with the
!> kept factors J = L D Lᵀ, reciprocal pivots), one backward sweep (Δu; u, v, a by the
!> Newmark relations), and the elements at the new state, one loop per kind: if no law
!> changed branch the step has converged, to round-off, with no further solve; otherwise J is
!> factorised on the new branches and Newton goes on. A step that does not settle in
!> MAX_FUSED solves, or meets a pivot ≤ 0, is taken by the general path (line search, chatter
!> rule, its failure messages): the answers are the general path's, to its Newton tolerance.
module martello_chain_newmark
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP, &
      L_YIELD, L_HARDENING, bilinear_return_map
   use martello_contact_laws, only: LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING, P_CLIP
   use martello_assembly, only: external_forces, uniform_acceleration
   use martello_time_functions, only: tf_value
   use martello_observer, only: observer_t, observer_work
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS, C_FUSED
   use martello_integrator_settings, only: integrator_settings_t, INT_NEWMARK
   use martello_fixed_step, only: contact_state
   use martello_generalized_alpha, only: generalized_alpha_t
   use martello_band_matrix, only: band_init
   implicit none
   private
   public :: chain_newmark_t, chain_fusable

   !> Fused Newton iterations before a step is handed to the general path: a step whose
   !> branches have not settled after this many exact linear solves is a chattering one.
   integer, parameter :: MAX_FUSED = 8

   !> Branches of the piecewise-linear laws (the tangent is constant on each).
   integer(int8), parameter :: B_OFF = 0, B_ON = 1, B_CLIPPED = 2, B_ELASTIC = 0, B_UPPER = 1, &
                               B_LOWER = -1

   type, extends(generalized_alpha_t) :: chain_newmark_t
      !> J = L D Lᵀ: reciprocal pivots rp(i) = 1/D_ii and g(i) = J(i, i+1)·rp(i) = L(i+1, i)
      real(dp), allocatable :: rp(:), g(:)
      !> nodal internal force at the iterate, the tangent's diagonal and J(i, i+1) parts from
      !> the elements, the forward-substituted right-hand side
      real(dp), allocatable :: fe(:), jd(:), jo(:), y(:)
      !> the tangent's damping part C_t (diagonal, C(i, i+1)) of the factors: the first
      !> iterate of a step is linearised about the committed state (as the general path's)
      real(dp), allocatable :: cd(:), co(:)
      !> the one parameter of each link and contact read in the sweep (k or c), contiguous
      real(dp), allocatable :: lpar(:), ck(:), cc(:)
      !> trial elongations and contact states, swapped with the committed ones of ms (links:
      !> the bilinear entries; the others are built for the recorded samples, link_states)
      real(dp), allocatable :: du_trial(:)
      logical, allocatable :: on_trial(:), clip(:)
      !> the model's links by kind: bilinear, and the others (springs, bars, dashpots)
      integer, allocatable :: bilinears(:), linears(:)
      !> the nodal forces as applied in fe (fe holds f_int − the nodal forces at t)
      real(dp), allocatable :: fnod(:)
      !> Σ m_i Δu_i of the step, and the uniform load acceleration at its start and end: the
      !> external work ½(a_n + a)·Σ m_i Δu_i (docs/run-layer.md) without a pass of its own
      real(dp) :: mdu = 0.0_dp, acc_n = 0.0_dp, acc = 0.0_dp
      !> branch of every bilinear link and contact at the last evaluation, and of the factors
      integer(int8), allocatable :: br_link(:), br_con(:), fac_link(:), fac_con(:)
      logical :: factored = .false.
      !> trapezoidal works of the last evaluation (dampers, other links, contacts)
      real(dp) :: wd = 0.0_dp, wl = 0.0_dp, wc = 0.0_dp
   contains
      procedure :: init => chain_init
      procedure :: step => chain_step
      procedure :: begin_step => chain_begin_step
      procedure :: link_states => chain_link_states
   end type chain_newmark_t

contains

   !> Whether the fused step runs this scene with these settings: Newmark, fused_chain on, a
   !> tridiagonal stiffness (half-bandwidth ≤ 1), lumped masses, piecewise-linear links and
   !> penalty contacts with the linear or Kelvin law, no stiffness block. Everything else takes
   !> the general path.
   logical function chain_fusable(m, s) result(ok)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      integer :: j
      ok = s%kind == INT_NEWMARK .and. logical(s%fused_chain)
      if (.not. ok) return
      ! stiffness blocks (frames) are not in the sweep's per-node parameters
      ok = model_bandwidth(m) <= 1 .and. m%ncoupling == 0 .and. m%nblock == 0
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR)
         case default
            ok = .false.
         end select
      end do
      do j = 1, m%ncontact
         if (m%con_scheme(j) /= SCHEME_PENALTY) ok = .false.
         if (m%con_law(j) /= LAW_LINEAR .and. m%con_law(j) /= LAW_KELVIN) ok = .false.
      end do
   end function chain_fusable

   subroutine chain_init(self, m, s, o, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: j, n, nl, nc
      call self%generalized_alpha_t%init(m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      n = m%n; nl = m%nlink; nc = m%ncontact
      allocate (self%rp(n), self%g(0:n), self%fe(0:n), self%jd(0:n), self%jo(0:n), self%y(0:n), &
                self%cd(0:n + 1), self%co(0:n + 1), self%lpar(nl), self%du_trial(nl), &
                self%ck(nc), self%cc(nc), self%on_trial(nc), self%clip(nc))
      allocate (self%br_link(nl), self%fac_link(nl), self%br_con(nc), self%fac_con(nc))
      do j = 1, nl
         self%lpar(j) = m%link_par(merge(L_DAMP, L_STIFF, m%link_kind(j) == LINK_DASHPOT), j)
      end do
      self%ck = m%con_par(P_STIFF, 1:nc)
      self%cc = merge(m%con_par(P_DAMPING, 1:nc), 0.0_dp, m%con_law(1:nc) == LAW_KELVIN)
      self%clip = m%con_law(1:nc) == LAW_KELVIN .and. m%con_par(P_CLIP, 1:nc) > 0.5_dp
      self%bilinears = pack([(j, j = 1, nl)], m%link_kind(1:nl) == LINK_BILINEAR)
      self%linears = pack([(j, j = 1, nl)], m%link_kind(1:nl) /= LINK_BILINEAR)
      allocate (self%fnod(m%nforce)); self%fnod = 0.0_dp
      self%own_link_peaks = .true.
      self%acc = uniform_acceleration(m, 0.0_dp)
      ! the general path's workspaces (three band matrices, seven vectors: ~260 B per DOF)
      ! are needed only for a step handed over; general_workspaces makes them then
      call band_init(self%jac, 0, 0); call band_init(self%mband, 0, 0)
      call band_init(self%cjac, 0, 0)
      deallocate (self%fint, self%fint_n, self%res, self%du, self%work, self%ma, self%man)
      self%br_link = B_ELASTIC; self%br_con = B_OFF
      self%g = 0.0_dp; self%y = 0.0_dp; self%cd = 0.0_dp; self%co = 0.0_dp
      self%factored = .false.
   end subroutine chain_init

   !> The committed state becomes the start of the next step by swapping the buffers: the
   !> step writes every entry of u, v, a before reading it.
   subroutine chain_begin_step(self)
      class(chain_newmark_t), intent(inout) :: self
      call swap(self%u, self%un); call swap(self%v, self%vn); call swap(self%a, self%an)
   end subroutine chain_begin_step

   subroutine chain_step(self, m, t, o, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: it, j, i
      logical :: flipped, ok
      real(dp) :: w_ext, f
      stat = MARTELLO_OK
      self%acc_n = self%acc
      self%acc = uniform_acceleration(m, t)
      self%mdu = 0.0_dp
      ok = .true.
      if (self%factored) then
         ! the first iterate: one solve with the kept factors about the committed state
         call nodal_forces(self, m, t)
         call linearised_sweep(self, m)
         call back_sweep(self, m, from_start=.true.)
      else
         call start_iterate(self)
      end if
      o%counters(C_NEWTON) = o%counters(C_NEWTON) + merge(1_i8, 0_i8, self%factored)
      do it = 1, MAX_FUSED
         call evaluate(self, m, o, flipped)
         call nodal_forces(self, m, t)
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         if (.not. flipped .and. self%factored) exit
         if (it == MAX_FUSED) ok = .false.
         if (.not. ok) exit
         call refactor_sweep(self, m, o, ok)
         if (.not. ok) exit
         call back_sweep(self, m, from_start=.false.)
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
      end do
      if (.not. ok) then
         ! the general path takes this step from the same committed state, with what it
         ! keeps and the fused step does not: the link states and f_ext at t_n
         self%factored = .false.
         call committed_links(self, m, self%un, self%vn)
         call external_forces(m, self%mrow, self%t0, self%fext)
         self%tangent_valid = .false.
         call general_workspaces(self)
         call self%generalized_alpha_t%step(m, t, o, stat)
         self%acc = uniform_acceleration(m, t)
         ! its link states are committed in ms: their peaks, which the fused step tracks
         do j = 1, m%nlink
            f = abs(self%ms%link_f(j))
            if (.not. (o%link_force_absmax(j) >= f)) o%link_force_absmax(j) = f
            f = abs(self%ms%link_u(j))
            if (.not. (o%link_du_absmax(j) >= f)) o%link_du_absmax(j) = f
         end do
         return
      end if
      call commit(self)
      o%counters(C_FUSED) = o%counters(C_FUSED) + 1_i8
      ! external work, trapezoidal as external_work: the uniform load on the masses and the
      ! nodal forces (fixed nodes have Δu = 0)
      w_ext = 0.5_dp*(self%acc_n + self%acc)*self%mdu
      do j = 1, m%nforce
         i = m%force_node(j)
         f = tf_value(m%force_fn(j), self%t0)
         w_ext = w_ext + 0.5_dp*(f + self%fnod(j))*(self%u(i) - self%un(i))
      end do
      call observer_work(o, damping=self%wd, links=self%wl, contact=self%wc)
      call observer_work(o, external=w_ext)
      call contact_state(self, m)
   end subroutine chain_step

   !> The workspaces of the general path, made on its first step (zero: the Newmark residual
   !> reads fint_n times α_f = 0).
   subroutine general_workspaces(self)
      class(chain_newmark_t), intent(inout) :: self
      integer :: n
      n = self%n
      if (allocated(self%fint)) return
      call band_init(self%jac, n, self%kd); call band_init(self%mband, n, self%kd)
      call band_init(self%cjac, n, self%kd)
      allocate (self%fint(0:n), self%fint_n(0:n), self%res(0:n), self%du(n), self%work(0:n), &
                self%ma(0:n), self%man(0:n))
      self%fint = 0.0_dp; self%fint_n = 0.0_dp; self%res = 0.0_dp; self%work = 0.0_dp
   end subroutine general_workspaces

   !> fe ← f_int − the nodal forces at t (fnod: those it holds now).
   subroutine nodal_forces(self, m, t)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      integer :: j
      real(dp) :: f
      do j = 1, m%nforce
         f = tf_value(m%force_fn(j), t)
         self%fe(m%force_node(j)) = self%fe(m%force_node(j)) + self%fnod(j) - f
         self%fnod(j) = f
      end do
   end subroutine nodal_forces

   !> ms%link_f, ms%link_u (and link_fc) of the springs, bars and dashpots at the state
   !> (u, v); the bilinear entries are kept committed by the step.
   subroutine committed_links(self, m, u, v)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: u(0:), v(0:)
      integer :: idx, j, a, b
      associate (ms => self%ms)
         do idx = 1, size(self%linears)
            j = self%linears(idx); a = m%link_a(j); b = m%link_b(j)
            ms%link_u(j) = u(a) - u(b)
            if (m%link_kind(j) == LINK_DASHPOT) then
               ms%link_f(j) = self%lpar(j)*(v(a) - v(b)); ms%link_fc(j) = 0.0_dp
            else
               ms%link_f(j) = self%lpar(j)*ms%link_u(j); ms%link_fc(j) = ms%link_f(j)
            end if
         end do
      end associate
   end subroutine committed_links

   !> The link states of the committed state, for a recorded sample.
   subroutine chain_link_states(self, m)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      call committed_links(self, m, self%u, self%v)
   end subroutine chain_link_states

   !> u = u_n with the Newmark a(u), v(u): the iterate a step starts from without factors.
   subroutine start_iterate(self)
      class(chain_newmark_t), intent(inout) :: self
      integer :: i
      real(dp) :: c1, c2, h, gm
      h = self%h; gm = self%gamma
      c1 = 1.0_dp/(self%beta*h); c2 = (0.5_dp - self%beta)/self%beta
      associate (u => self%u, v => self%v, a => self%a, un => self%un, vn => self%vn, an => self%an)
         do i = 0, self%n
            u(i) = un(i)
            a(i) = -c1*vn(i) - c2*an(i)
            v(i) = vn(i) + h*((1.0_dp - gm)*an(i) + gm*a(i))
         end do
      end associate
   end subroutine start_iterate

   !> The forward sweep of the first iterate: the residual at u = u_n linearised about the
   !> committed state, r = M a₀ + f_c + C_t Δv₀ − f_ext (exact while no branch changes: the
   !> laws are affine on a branch), forward-substituted with the kept factors; v, a ← the
   !> Newmark v₀, a₀ of u = u_n.
   subroutine linearised_sweep(self, m)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer :: i, n
      real(dp) :: c1, c2, h, gm, dvm, dv0, dvp, a0, ap, cdv
      n = self%n; h = self%h; gm = self%gamma
      c1 = 1.0_dp/(self%beta*h); c2 = (0.5_dp - self%beta)/self%beta
      associate (v => self%v, a => self%a, vn => self%vn, an => self%an, mass => m%mass, &
                 fe => self%fe, acc => self%acc, g => self%g, y => self%y, cd => self%cd, &
                 co => self%co)
         dvm = 0.0_dp
         a0 = -c1*vn(1) - c2*an(1)
         dv0 = h*((1.0_dp - gm)*an(1) + gm*a0)
         do i = 1, n
            ap = 0.0_dp; dvp = 0.0_dp
            if (i < n) then
               ap = -c1*vn(i + 1) - c2*an(i + 1)
               dvp = h*((1.0_dp - gm)*an(i + 1) + gm*ap)
            end if
            cdv = cd(i)*dv0 + co(i - 1)*dvm + co(i)*dvp
            y(i) = mass(i)*(acc - a0) - fe(i) - cdv - g(i - 1)*y(i - 1)
            a(i) = a0; v(i) = vn(i) + dv0
            dvm = dv0; dv0 = dvp; a0 = ap
         end do
         a(0) = 0.0_dp; v(0) = 0.0_dp
         call pin_fixed(self)
      end associate
   end subroutine linearised_sweep

   !> The forward sweep of a Newton iterate after a branch change: the tangent on the current
   !> branches, J = c_m M + K_t + c_v C_t = L D Lᵀ (reciprocal pivots), and the residual
   !> r = M a + f_int − f_ext forward-substituted. ok = .false. on a pivot that is not > 0.
   subroutine refactor_sweep(self, m, o, ok)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      logical, intent(out) :: ok
      integer :: i
      real(dp) :: p, cm
      cm = self%cm
      call tangent(self, m)
      self%fac_link = self%br_link; self%fac_con = self%br_con
      o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      ok = .true.
      associate (a => self%a, mass => m%mass, fe => self%fe, acc => self%acc, rp => self%rp, &
                 g => self%g, y => self%y, jd => self%jd, jo => self%jo)
         do i = 1, self%n
            p = cm*mass(i) + jd(i) - jo(i - 1)*g(i - 1)
            if (.not. (p > 0.0_dp)) ok = .false.
            rp(i) = 1.0_dp/p
            g(i) = jo(i)*rp(i)
            y(i) = mass(i)*(acc - a(i)) - fe(i) - g(i - 1)*y(i - 1)
         end do
      end associate
      self%g(self%n) = 0.0_dp
      self%factored = ok
      call pin_fixed(self)
   end subroutine refactor_sweep

   !> Fixed rows carry no residual: their Δu is 0 (their column of the factors is 0, so no
   !> other row depends on their entry of y).
   subroutine pin_fixed(self)
      class(chain_newmark_t), intent(inout) :: self
      integer :: k
      do k = 1, size(self%fixed_nodes)
         self%y(self%fixed_nodes(k)) = 0.0_dp
      end do
   end subroutine pin_fixed

   !> The backward sweep: Δu = D⁻¹y − Lᵀ Δu, and u, v, a by the Newmark relations
   !> (Δa = c_m Δu, Δv = c_v Δu), Σ m_i Δu_i for the external work; from_start: the iterate
   !> was u = u_n.
   subroutine back_sweep(self, m, from_start)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(in) :: from_start
      integer :: i
      real(dp) :: x, cm, cv, mdu
      cm = self%cm; cv = self%cv
      mdu = 0.0_dp
      associate (u => self%u, v => self%v, a => self%a, un => self%un, rp => self%rp, &
                 g => self%g, y => self%y, mass => m%mass)
         x = 0.0_dp
         if (from_start) then
            do i = self%n, 1, -1
               x = rp(i)*y(i) - g(i)*x
               u(i) = un(i) + x; v(i) = v(i) + cv*x; a(i) = a(i) + cm*x
               mdu = mdu + mass(i)*x
            end do
            u(0) = 0.0_dp
         else
            do i = self%n, 1, -1
               x = rp(i)*y(i) - g(i)*x
               u(i) = u(i) + x; v(i) = v(i) + cv*x; a(i) = a(i) + cm*x
               mdu = mdu + mass(i)*x
            end do
         end if
      end associate
      self%mdu = self%mdu + mdu
   end subroutine back_sweep

   !> The elements at the iterate (u, v), one loop per kind (contacts, bilinear links, the
   !> linear links): trial forces, the nodal internal force fe, the branch of every
   !> piecewise-linear law, and the trapezoidal works of the step were it to end here, as
   !> mech_commit sums them (½(f_n + f)·Δ, f_n of the springs and dashpots from the committed
   !> state). flipped: a branch differs from the factors'. When none does and the factors
   !> are kept, this is the step's state: the link peaks are tracked here, not in a pass of
   !> their own (the observer's o%link_*_absmax, own_link_peaks).
   subroutine evaluate(self, m, o, flipped)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      logical, intent(out) :: flipped
      integer :: j, a, b, idx
      real(dp) :: du, dun, f, fn, kt, pen, wd, wl, wc
      logical :: yielding, on, final
      integer(int8) :: br
      flipped = .false.
      wd = 0.0_dp; wl = 0.0_dp; wc = 0.0_dp
      associate (u => self%u, v => self%v, un => self%un, vn => self%vn, fe => self%fe, &
                 ms => self%ms, par => m%link_par, la => m%link_a, lb => m%link_b, &
                 kind => m%link_kind, lpar => self%lpar, ca => m%con_a, cb => m%con_b, &
                 gap => m%con_gap, ck => self%ck, cc => self%cc, fmax => o%link_force_absmax, &
                 dmax => o%link_du_absmax)
         fe = 0.0_dp
         do j = 1, m%ncontact
            a = ca(j); b = cb(j)
            pen = u(a) - u(b) - gap(j)
            on = pen > 0.0_dp
            br = B_OFF; f = 0.0_dp
            if (on) then
               ! linear (cc = 0) or Kelvin (Anagnostopoulos 1988), as martello_contact_laws
               br = B_ON
               f = ck(j)*pen + cc(j)*(v(a) - v(b))
               if (self%clip(j) .and. f <= 0.0_dp) then
                  f = 0.0_dp; br = B_CLIPPED
               end if
            end if
            self%br_con(j) = br
            flipped = flipped .or. br /= self%fac_con(j)
            ms%con_pen_trial(j) = pen; ms%con_f_trial(j) = f; self%on_trial(j) = on
            wc = wc + 0.5_dp*(ms%con_f(j) + f)*(pen - ms%con_pen(j))
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         do idx = 1, size(self%bilinears)
            ! the return map from the committed state
            j = self%bilinears(idx); a = la(j); b = lb(j)
            du = u(a) - u(b)
            call bilinear_return_map(par(L_STIFF, j), par(L_YIELD, j), par(L_HARDENING, j), &
                                     ms%link_fc(j), ms%link_u(j), du, f, kt, yielding)
            br = B_ELASTIC
            if (yielding) br = merge(B_UPPER, B_LOWER, f > par(L_HARDENING, j)*par(L_STIFF, j)*du)
            self%br_link(j) = br
            flipped = flipped .or. br /= self%fac_link(j)
            wl = wl + 0.5_dp*(ms%link_f(j) + f)*(du - ms%link_u(j))
            ms%link_f_trial(j) = f; ms%link_fc_trial(j) = f; self%du_trial(j) = du
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         final = self%factored .and. .not. flipped
         do idx = 1, size(self%linears)
            j = self%linears(idx); a = la(j); b = lb(j)
            du = u(a) - u(b); dun = un(a) - un(b)
            if (kind(j) == LINK_DASHPOT) then
               f = lpar(j)*(v(a) - v(b)); fn = lpar(j)*(vn(a) - vn(b))
               wd = wd + 0.5_dp*(fn + f)*(du - dun)
            else
               f = lpar(j)*du; fn = lpar(j)*dun
               wl = wl + 0.5_dp*(fn + f)*(du - dun)
            end if
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
            ! written as "not ≥" so that the NaN the maxima start from is replaced
            if (final) then
               if (.not. (fmax(j) >= abs(f))) fmax(j) = abs(f)
               if (.not. (dmax(j) >= abs(du))) dmax(j) = abs(du)
            end if
         end do
         if (final) then
            do idx = 1, size(self%bilinears)
               j = self%bilinears(idx)
               if (.not. (fmax(j) >= abs(ms%link_f_trial(j)))) fmax(j) = abs(ms%link_f_trial(j))
               if (.not. (dmax(j) >= abs(self%du_trial(j)))) dmax(j) = abs(self%du_trial(j))
            end do
         end if
         fe(0) = 0.0_dp
      end associate
      self%fnod = 0.0_dp
      self%wd = wd; self%wl = wl; self%wc = wc
   end subroutine evaluate

   !> Accept the last evaluation: committed ← trial by swapping the arrays (as mech_commit
   !> does, whose works evaluate has already summed).
   subroutine commit(self)
      class(chain_newmark_t), intent(inout) :: self
      logical, allocatable :: tmp(:)
      associate (ms => self%ms)
         call swap(ms%link_f, ms%link_f_trial); call swap(ms%link_fc, ms%link_fc_trial)
         call swap(ms%link_u, self%du_trial)
         call swap(ms%con_f, ms%con_f_trial); call swap(ms%con_pen, ms%con_pen_trial)
         call move_alloc(ms%con_on, tmp); call move_alloc(self%on_trial, ms%con_on)
         call move_alloc(tmp, self%on_trial)
      end associate
   end subroutine commit

   !> The tangent of every element on its current branch: jd (diagonal) and jo (J(i, i+1))
   !> of K_t + c_v C_t, and C_t alone in cd, co; fixed rows and columns pinned to the
   !> identity.
   subroutine tangent(self, m)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer :: idx, j, i
      real(dp) :: k
      associate (par => m%link_par, cv => self%cv)
         self%jd = 0.0_dp; self%jo = 0.0_dp; self%cd = 0.0_dp; self%co = 0.0_dp
         do j = 1, m%nlink
            select case (m%link_kind(j))
            case (LINK_SPRING, LINK_BAR)
               call stencil(m%link_a(j), m%link_b(j), self%lpar(j), 0.0_dp)
            case (LINK_DASHPOT)
               call stencil(m%link_a(j), m%link_b(j), 0.0_dp, self%lpar(j))
            case default
               k = par(L_STIFF, j)
               if (self%br_link(j) /= B_ELASTIC) k = par(L_HARDENING, j)*k
               call stencil(m%link_a(j), m%link_b(j), k, 0.0_dp)
            end select
         end do
         do j = 1, m%ncontact
            if (self%br_con(j) == B_ON) call stencil(m%con_a(j), m%con_b(j), self%ck(j), self%cc(j))
         end do
         do idx = 1, size(self%fixed_nodes)
            i = self%fixed_nodes(idx)
            self%jd(i) = 1.0_dp - self%cm*m%mass(i)
            self%jo(i) = 0.0_dp; self%jo(i - 1) = 0.0_dp
            self%cd(i) = 0.0_dp; self%co(i) = 0.0_dp; self%co(i - 1) = 0.0_dp
         end do
         self%jo(0) = 0.0_dp; self%jo(self%n) = 0.0_dp; self%co(0) = 0.0_dp; self%co(self%n) = 0.0_dp
      end associate
   contains
      !> J += k + c_v c, C_t += c on the two-node stencil of (i, k): |i − k| ≤ 1 or one end
      !> on ground (0).
      subroutine stencil(i, l, k, c)
         integer, intent(in) :: i, l
         real(dp), intent(in) :: k, c
         real(dp) :: val
         val = k + self%cv*c
         self%jd(i) = self%jd(i) + val; self%jd(l) = self%jd(l) + val
         self%cd(i) = self%cd(i) + c; self%cd(l) = self%cd(l) + c
         if (i > 0 .and. l > 0) then
            self%jo(min(i, l)) = self%jo(min(i, l)) - val
            self%co(min(i, l)) = self%co(min(i, l)) - c
         end if
      end subroutine stencil
   end subroutine tangent

   subroutine swap(x, y)
      real(dp), allocatable, intent(inout) :: x(:), y(:)
      real(dp), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap
end module martello_chain_newmark
