!> The fused chain step (docs/run-layer.md "The fused chain step"): Newmark (β, γ) on a chain,
!> a scene whose effective stiffness is tridiagonal (every link and contact couples nodes i
!> and i ± 1, or a node and ground; lumped masses) and whose laws are piecewise linear
!> (springs, bars, dashpots, bilinear springs; linear and Kelvin penalty contacts).
!>
!> Newton's method on the step equations, as the general path (martello_generalized_alpha)
!> does, but on such a scene one Newton step from a state is exact as long as no law changes
!> branch between the linearisation and the new iterate. The scene is held per node
!> (structure of arrays): the linear links of a node to ground and of a node pair summed, the
!> first contact of each pair with its law resolved once for all pairs; the other elements
!> (bilinear springs, contacts to ground, a second contact on a pair) one by one. A step is a
!> forward sweep (the residual at u = uₙ linearised about the committed state, forward
!> substitution with the kept factors J = L D Lᵀ, reciprocal pivots) and a backward sweep that
!> solves for Δu, updates u, v, a by the Newmark relations and evaluates the elements of each
!> node and pair as it goes (forces, branches, works): the kernels of
!> martello_chain_kernels. If no law changed branch the step has converged, to round-off,
!> with no further solve; otherwise J is factorised on the new branches and Newton goes on.
!> A step that does not settle in MAX_FUSED solves, or meets a pivot ≤ 0, is taken by the
!> general path (line search, chatter rule, its failure messages): the answers are the
!> general path's, to its Newton tolerance. The step measures itself (measures_itself): it
!> hands its states to the observer's bulk entry, observer_block.
module martello_chain_step
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp, i8
   use martello_status
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY, model_link_index, &
      model_initial_state, model_contact_index, model_contact_at, model_expanded
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP, &
      L_YIELD, L_HARDENING, bilinear_return_map, bilinear_energy
   use martello_contact_laws, only: LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING, P_CLIP, &
      P_RESTITUTION, NPAR_CONTACT, contact_elastic_energy, damping_from_restitution, BRANCH_OFF, &
      BRANCH_ON, BRANCH_CLIPPED, AFFINE_LINEAR, AFFINE_KELVIN, AFFINE_KELVIN_CLIPPED
   use martello_effective_mass, only: pair_effective_mass, effective_mass_prepare
   use martello_assembly, only: external_forces, uniform_acceleration, internal_forces, mech_commit
   use martello_time_functions, only: tf_value
   use martello_observer, only: observer_t, node_block_t, observer_fail, observer_failed, &
      observer_work, observer_begin, observer_block, observer_open_phase, observer_energy_due
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS, C_FUSED
   use martello_integrator_settings, only: integrator_settings_t, INT_NEWMARK
   use martello_fixed_step, only: stepper_t
   use martello_generalized_alpha, only: generalized_alpha_t
   use martello_chain_kernels, only: forward_kernel, refactor_kernel, back_kernel
   implicit none
   private
   public :: chain_step_t, chain_fusable

   !> Fused Newton iterations before a step is handed to the general path: a step whose
   !> branches have not settled after this many exact linear solves is a chattering one.
   integer, parameter :: MAX_FUSED = 8

   !> Branches of the bilinear springs (the tangent is constant on each); the contacts' are
   !> martello_contact_laws' BRANCH_*.
   integer(int8), parameter :: B_ELASTIC = 0, B_UPPER = 1, B_LOWER = -1

   type, extends(stepper_t) :: chain_step_t
      type(integrator_settings_t) :: settings
      !> Newmark: Δa = c_m Δu, Δv = c_v Δu; the iterate u = uₙ has a₀ = −c₁vₙ − c₂aₙ
      real(dp) :: beta = 0.25_dp, gamma = 0.5_dp, cm = 0.0_dp, cv = 0.0_dp, c1 = 0.0_dp, &
                  c2 = 0.0_dp
      !> the masses, read at 1 + (i − 1)·sm: one value for every node (sm = 0) or each's
      real(dp), allocatable :: mass(:)
      integer :: sm = 1
      !> the linear links (springs, bars, dashpots) summed: of node i to ground (kg, cg,
      !> 1:n), of the pair (i, i+1) (kp, cp, 0:n with 0 and n zero; allocated if any)
      real(dp), allocatable :: kg(:), cg(:), kp(:), cp(:)
      logical :: pair_links = .false.
      !> the links are those of the model's one chain on every node, dashpots included: kg and
      !> cg are its k and c, read there (no copy)
      logical :: chain_links = .false.
      !> the pair contacts (of (i, i+1), i < n) with their laws, and the other elements one by
      !> one (node_block_t, what observer_block reads too)
      type(node_block_t) :: blk
      !> pair contact branches: trial (of the last evaluation), committed, of the factors
      integer(int8), allocatable :: pbr(:), pbrc(:), pbrf(:)
      !> the other elements, one by one (blk: their indices): the bilinear links' committed
      !> force and elongation, trial, branch of the last evaluation and of the factors; the
      !> other contacts' branches
      real(dp), allocatable :: bfc(:), bdu(:), bft(:), bdut(:)
      integer(int8), allocatable :: bbr(:), bbrf(:), xbr(:), xbrc(:), xbrf(:)
      !> their tangents on the factors' branches per node: J (diagonal, J(i, i+1)) and C_t
      real(dp), allocatable :: xjd(:), xjo(:), xcd(:), xco(:)
      logical :: others = .false.
      !> J = L D Lᵀ: reciprocal pivots rp(i) = 1/D_ii (L(i+1, i) = J(i, i+1)·rp(i) is computed
      !> again where a sweep needs it, coupling: no array of it); fe the nodal internal force
      !> at the last evaluation minus the nodal forces (fnod, as applied), which the forward
      !> sweeps overwrite, entry by entry as they read it, with the forward-substituted
      !> right-hand side y, and the backward sweep, entry by entry after reading y, with the
      !> internal force again: one array for both
      real(dp), allocatable :: rp(:), fe(:), fnod(:)
      !> a node is fixed (its row and column of J are the identity's)
      logical :: any_fixed = .false.
      logical :: factored = .false.
      !> Σ m_i Δu_i of the step, and the uniform load acceleration at its start and end: the
      !> external work ½(a_n + a)·Σ m_i Δu_i (docs/run-layer.md) without a pass of its own
      real(dp) :: mdu = 0.0_dp, acc_n = 0.0_dp, acc = 0.0_dp
      !> trapezoidal works of the last evaluation (dampers, other links, contacts)
      real(dp) :: wd = 0.0_dp, wl = 0.0_dp, wc = 0.0_dp
      !> the general path, made at the first step handed to it, and the model with its chains
      !> as links and contacts one by one, for it (when the model has chains)
      type(generalized_alpha_t), allocatable :: gen
      type(model_t), allocatable :: gm
   contains
      procedure :: from_chain_of_one_kind
      procedure :: init => chain_init
      procedure :: step => chain_step
      procedure :: begin_step => chain_begin_step
      procedure :: measure_start => chain_measure_start
      procedure :: measure => chain_measure
   end type chain_step_t

   interface
      !> The chain per node from the model's links and contacts (fortran/chain/per_node.f90).
      module subroutine per_node(self, m, st)
         class(chain_step_t), intent(inout) :: self
         type(model_t), intent(in) :: m
         integer, intent(out) :: st
      end subroutine per_node
   end interface

contains

   !> Whether the fused step runs this scene with these settings: Newmark with 2β ≥ γ
   !> (unconditionally stable: no stability limit to check), fused_chain on, a tridiagonal
   !> stiffness (half-bandwidth ≤ 1), lumped masses, piecewise-linear links and penalty
   !> contacts with the linear or Kelvin law, no stiffness block. Everything else takes the
   !> general path.
   logical function chain_fusable(m, s) result(ok)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      integer :: j, q
      logical, allocatable :: paired(:)
      ok = s%kind == INT_NEWMARK .and. logical(s%fused_chain) .and. 2.0_dp*s%beta >= s%gamma
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
      ! a chain held per node: linear springs (its bilinear ones are taken one by one), and
      ! contacts the sweep holds as pair contacts (one chain's to a pair)
      ! a scene whose few bytes per node cannot be had is not fused (the general path then
      ! reports its own out-of-memory line)
      allocate (paired(0:m%n), stat=j)
      if (j /= 0) then
         ok = .false.; return
      end if
      paired = .false.
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            if (allocated(ch%fy)) ok = .false.
            if (ch%ncontact == 0) cycle
            if (ch%scheme /= SCHEME_PENALTY) ok = .false.
            if (ch%law /= LAW_LINEAR .and. ch%law /= LAW_KELVIN) ok = .false.
            if (any(paired(ch%first:ch%first + ch%n - 2))) ok = .false.
            paired(ch%first:ch%first + ch%n - 2) = .true.
         end associate
      end do
   end function chain_fusable

   !> The scene per node, and the state at t = 0 with a = M⁻¹(f_ext − f_int).
   subroutine chain_init(self, m, s, o, stat)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, i, st
      logical :: flipped
      character(len=16) :: num
      character(len=512) :: msg
      stat = MARTELLO_OK
      n = m%n
      self%n = n; self%nc = m%ncontact; self%h = s%dt; self%settings = s
      self%beta = s%beta; self%gamma = s%gamma
      self%cm = 1.0_dp/(s%beta*s%dt*s%dt); self%cv = s%gamma/(s%beta*s%dt)
      self%c1 = 1.0_dp/(s%beta*s%dt); self%c2 = (0.5_dp - s%beta)/s%beta
      self%sm = merge(0, 1, all(m%mass == m%mass(1)))
      self%advice = 'the step is past the stability limit'
      self%measures_itself = .true.
      ! st: every allocation of the per-node state (stat > 0 if one failed)
      allocate (self%mass(merge(1, n, self%sm == 0)), self%fixed_nodes(count(m%fixed)), &
                self%u(0:n), self%v(0:n), self%a(0:n), self%un(0:n), self%vn(0:n), self%an(0:n), &
                self%pen(0), self%force(0), self%rp(n), self%fe(0:n), self%fnod(m%nforce), stat=st)
      if (st == 0) call per_node(self, m, st)
      if (st /= 0) then
         write (num, '(i0)') n
         call out_of_memory('the per-node state of the fused chain step for '//trim(num)//' nodes', &
                            -1.0_dp, FIX_SMALLER_SCENE, stat, msg)
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%mass = m%mass(1:size(self%mass))
      self%u(0) = 0.0_dp; self%v(0) = 0.0_dp
      call model_initial_state(m, self%u(1:n), self%v(1:n))
      self%fixed_nodes = pack([(i, i = 1, n)], m%fixed)
      ! the bilinear springs start elastic, on k·Δu₀ (clamped into the band by the first
      ! step), as mech_init
      do i = 1, size(self%blk%bl)
         self%bdu(i) = self%u(m%link_a(self%blk%bl(i))) - self%u(m%link_b(self%blk%bl(i)))
         self%bfc(i) = m%link_par(L_STIFF, self%blk%bl(i))*self%bdu(i)
      end do
      self%rp = 0.0_dp; self%fe = 0.0_dp; self%fnod = 0.0_dp
      self%any_fixed = size(self%fixed_nodes) > 0
      ! the elements at (u0, v0) with their whole laws: the evaluation at an iterate with no
      ! increment, works from (u0, v0) itself
      self%un = self%u; self%vn = self%v; self%a = 0.0_dp; self%an = 0.0_dp
      self%acc = uniform_acceleration(m, 0.0_dp)
      call evaluate(self, m, .false., flipped)
      call nodal_forces(self, m, 0.0_dp)
      ! M a = f_ext − f_int on the free nodes: M is diagonal (counted as the general path's
      ! factorisation of M)
      do i = 1, n
         self%a(i) = 0.0_dp
         if (.not. m%fixed(i)) self%a(i) = (m%mass(i)*self%acc - self%fe(i))/m%mass(i)
      end do
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      call commit(self)
      self%un = self%u; self%vn = self%v; self%an = self%a
      self%factored = .false.
   end subroutine chain_init

   !> The committed state becomes the start of the next step by swapping the buffers: the
   !> step writes every entry of u, v, a before reading it.
   subroutine chain_begin_step(self)
      class(chain_step_t), intent(inout) :: self
      call swap(self%u, self%un); call swap(self%v, self%vn); call swap(self%a, self%an)
   end subroutine chain_begin_step

   subroutine chain_step(self, m, t, o, stat)
      class(chain_step_t), intent(inout) :: self
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
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
      else
         ! no factors: the elements at u = u_n (a solve with zero factors is no increment)
         self%rp = 0.0_dp; self%fe = 0.0_dp
      end if
      call evaluate(self, m, .true., flipped)
      call nodal_forces(self, m, t)
      o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
      do it = 1, MAX_FUSED
         if (.not. flipped .and. self%factored) exit
         if (it == MAX_FUSED) ok = .false.
         if (.not. ok) exit
         call refactor_sweep(self, m, o, ok)
         if (.not. ok) exit
         call evaluate(self, m, .false., flipped)
         call nodal_forces(self, m, t)
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
      end do
      if (.not. ok) then
         call general_step(self, m, t, o, stat)
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
   end subroutine chain_step

   !> fe ← f_int − the nodal forces at t (fnod: those it holds now).
   subroutine nodal_forces(self, m, t)
      class(chain_step_t), intent(inout) :: self
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

   !> The forward sweep of the first iterate: the residual at u = u_n linearised about the
   !> committed state, r = M a₀ + f_c + C_t Δv₀ − f_ext (exact while no branch changes: the
   !> laws are affine on a branch), forward-substituted with the kept factors. a₀, Δv₀: the
   !> Newmark a and v − vₙ of u = u_n; C_t the damping tangent on the factors' branches.
   subroutine linearised_sweep(self, m)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      if (self%chain_links) then
         call sweep(m%chain(1)%c)
      else
         call sweep(self%cg)
      end if
      call pin_fixed(self)
   contains
      subroutine sweep(cg)
         real(dp), intent(in), contiguous :: cg(:)
         if (.not. (self%pair_links .or. self%blk%kelvin .or. self%others) .and. &
             self%from_chain_of_one_kind()) then
            ! the usual chain, with these as constants (back_kernel's call says why)
            call forward_kernel(self%n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                .false., .false., .false., self%blk%pairs, .false., 0, 0, &
                                self%vn, self%an, 0, self%mass, self%fe, self%rp, cg, self%kp, &
                                self%cp, self%blk%k, self%blk%c, self%pbrf, self%xcd, self%xco, &
                                self%xjo, m%fixed)
         else
            call forward_kernel(self%n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                self%pair_links, self%blk%kelvin, self%others, self%blk%pairs, &
                                self%any_fixed, self%blk%sk, self%blk%sc, self%vn, self%an, self%sm, &
                                self%mass, self%fe, self%rp, cg, self%kp, self%cp, self%blk%k, &
                                self%blk%c, self%pbrf, self%xcd, self%xco, self%xjo, m%fixed)
         end if
      end subroutine sweep
   end subroutine linearised_sweep

   !> The forward sweep of a Newton iterate after a branch change: the tangent on the current
   !> branches, J = c_m M + K_t + c_v C_t = L D Lᵀ (reciprocal pivots; fixed rows and columns
   !> the identity's), and the residual r = M a + f_int − f_ext forward-substituted.
   !> ok = .false. on a pivot that is not > 0.
   subroutine refactor_sweep(self, m, o, ok)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      logical, intent(out) :: ok
      if (self%others) call others_tangent(self, m)
      self%pbrf = self%pbr; self%bbrf = self%bbr; self%xbrf = self%xbr
      o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      if (self%chain_links) then
         call sweep(m%chain(1)%k, m%chain(1)%c)
      else
         call sweep(self%kg, self%cg)
      end if
      self%factored = ok
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         call refactor_kernel(self%n, self%cm, self%cv, self%acc, self%pair_links, &
                              self%blk%pairs, self%others, self%blk%sk, self%blk%sc, self%a, self%sm, &
                              self%mass, m%fixed, self%fe, kg, cg, self%kp, self%cp, self%blk%k, &
                              self%blk%c, self%pbr, self%xjd, self%xjo, self%rp, ok)
      end subroutine sweep
   end subroutine refactor_sweep

   !> Fixed rows carry no residual: their Δu is 0 (their column of the factors is 0, so no
   !> other row depends on their entry of y).
   subroutine pin_fixed(self)
      class(chain_step_t), intent(inout) :: self
      integer :: k
      do k = 1, size(self%fixed_nodes)
         self%fe(self%fixed_nodes(k)) = 0.0_dp
      end do
   end subroutine pin_fixed

   !> The backward sweep and the elements at the new iterate: Δu = D⁻¹y − Lᵀ Δu, and u, v, a
   !> by the Newmark relations (Δa = c_m Δu, Δv = c_v Δu; from_start: from u = u_n, a₀, v₀,
   !> else from the current iterate); as each node and pair is known, its linear links and
   !> pair contact: the nodal internal force fe, each pair contact's branch, and the
   !> trapezoidal works of the step were it to end here, as mech_commit sums them
   !> (½(f_n + f)·Δ, f_n from the committed state); then the other elements (others).
   !> flipped: a branch differs from the factors'. Σ m_i Δu_i for the external work.
   subroutine evaluate(self, m, from_start, flipped)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(in) :: from_start
      logical, intent(out) :: flipped
      real(dp) :: mdu
      if (self%chain_links) then
         call sweep(m%chain(1)%k, m%chain(1)%c)
      else
         call sweep(self%kg, self%cg)
      end if
      self%mdu = self%mdu + mdu
      if (self%others) call others(self, m, flipped)
      self%fnod = 0.0_dp
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         if (.not. (self%pair_links .or. self%blk%kelvin) .and. self%blk%pairs .and. &
             self%from_chain_of_one_kind()) then
            ! the usual chain (springs and dashpots to ground, one linear contact law and gap
            ! for every pair, one mass): the same kernel with these as constants, which the
            ! compiler specialises (no branches on them, the parameters read once)
            call back_kernel(self%n, from_start, .false., .true., .false., .false., .false., 0, 0, &
                             0, 0, 0, self%cm, self%cv, self%c1, self%c2, self%h, self%gamma, &
                             self%rp, self%u, self%v, self%a, self%un, self%vn, self%an, 0, &
                             self%mass, self%fe, kg, cg, self%kp, self%cp, self%blk%sgn, self%blk%gap, &
                             self%blk%k, self%blk%c, self%blk%law, self%pbr, self%pbrc, self%pbrf, &
                             self%xjo, m%fixed, mdu, self%wd, self%wl, self%wc, flipped)
         else
            call back_kernel(self%n, from_start, self%pair_links, self%blk%pairs, self%blk%kelvin, &
                             self%others, self%any_fixed, self%blk%ss, self%blk%sg, self%blk%sk, self%blk%sc, &
                             self%blk%sl, self%cm, self%cv, self%c1, self%c2, self%h, self%gamma, &
                             self%rp, self%u, self%v, self%a, self%un, self%vn, self%an, self%sm, &
                             self%mass, self%fe, kg, cg, self%kp, self%cp, self%blk%sgn, self%blk%gap, &
                             self%blk%k, self%blk%c, self%blk%law, self%pbr, self%pbrc, self%pbrf, &
                             self%xjo, m%fixed, mdu, self%wd, self%wl, self%wc, flipped)
         end if
      end subroutine sweep
   end subroutine evaluate

   !> The bilinear links and the other contacts at the iterate, one by one (after the sweep:
   !> fe holds the rest): forces into fe, branches, works.
   subroutine others(self, m, flipped)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(inout) :: flipped
      integer :: idx, j, a, b
      real(dp) :: du, f, kt, pen, penn, fn
      logical :: yielding
      integer(int8) :: br
      associate (u => self%u, v => self%v, un => self%un, vn => self%vn, fe => self%fe, &
                 par => m%link_par)
         do idx = 1, size(self%blk%bl)
            ! the return map from the committed state
            j = self%blk%bl(idx); a = m%link_a(j); b = m%link_b(j)
            du = u(a) - u(b)
            call bilinear_return_map(par(L_STIFF, j), par(L_YIELD, j), par(L_HARDENING, j), &
                                     self%bfc(idx), self%bdu(idx), du, f, kt, yielding)
            br = B_ELASTIC
            if (yielding) br = merge(B_UPPER, B_LOWER, f > par(L_HARDENING, j)*par(L_STIFF, j)*du)
            self%bbr(idx) = br
            flipped = flipped .or. br /= self%bbrf(idx)
            self%wl = self%wl + 0.5_dp*(self%bfc(idx) + f)*(du - self%bdu(idx))
            self%bft(idx) = f; self%bdut(idx) = du
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         do idx = 1, size(self%blk%xg)
            j = self%blk%xg(idx); a = m%con_a(j); b = m%con_b(j)
            pen = u(a) - u(b) - m%con_gap(j)
            call contact_law(m, j, pen, v(a) - v(b), br, f)
            self%xbr(idx) = br
            flipped = flipped .or. br /= self%xbrf(idx)
            penn = un(a) - un(b) - m%con_gap(j)
            call contact_law(m, j, penn, vn(a) - vn(b), br, fn, self%xbrc(idx))
            self%wc = self%wc + 0.5_dp*(fn + f)*(pen - penn)
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         fe(0) = 0.0_dp
      end associate
   end subroutine others

   !> Contact j's force f at δ = pen, δ̇ = rate and its branch br: on its whole law, or on
   !> the given branch on (the committed one).
   subroutine contact_law(m, j, pen, rate, br, f, on)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: pen, rate
      integer(int8), intent(out) :: br
      real(dp), intent(out) :: f
      integer(int8), intent(in), optional :: on
      br = BRANCH_OFF; f = 0.0_dp
      if (present(on)) then
         if (on /= BRANCH_ON) return
      else if (.not. (pen > 0.0_dp)) then
         return
      end if
      br = BRANCH_ON
      f = m%con_par(P_STIFF, j)*pen
      if (m%con_law(j) == LAW_KELVIN) then
         f = f + m%con_par(P_DAMPING, j)*rate
         if (.not. present(on) .and. m%con_par(P_CLIP, j) > 0.5_dp .and. f <= 0.0_dp) then
            f = 0.0_dp; br = BRANCH_CLIPPED
         end if
      end if
   end subroutine contact_law

   !> The other elements' tangents on their current branches, per node: xjd, xjo of
   !> K_t + c_v C_t and C_t alone in xcd, xco (what the factors are made with).
   subroutine others_tangent(self, m)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer :: idx, j
      real(dp) :: k, c
      self%xjd = 0.0_dp; self%xjo = 0.0_dp; self%xcd = 0.0_dp; self%xco = 0.0_dp
      do idx = 1, size(self%blk%bl)
         j = self%blk%bl(idx)
         k = m%link_par(L_STIFF, j)
         if (self%bbr(idx) /= B_ELASTIC) k = m%link_par(L_HARDENING, j)*k
         call stencil(m%link_a(j), m%link_b(j), k, 0.0_dp)
      end do
      do idx = 1, size(self%blk%xg)
         j = self%blk%xg(idx)
         if (self%xbr(idx) /= BRANCH_ON) cycle
         c = 0.0_dp
         if (m%con_law(j) == LAW_KELVIN) c = m%con_par(P_DAMPING, j)
         call stencil(m%con_a(j), m%con_b(j), m%con_par(P_STIFF, j), c)
      end do
      self%xjd(0) = 0.0_dp; self%xcd(0) = 0.0_dp
   contains
      !> J += k + c_v c, C_t += c on the two-node stencil of (i, l): |i − l| ≤ 1 or one end
      !> on ground (0).
      subroutine stencil(i, l, k, c)
         integer, intent(in) :: i, l
         real(dp), intent(in) :: k, c
         real(dp) :: val
         val = k + self%cv*c
         self%xjd(i) = self%xjd(i) + val; self%xjd(l) = self%xjd(l) + val
         self%xcd(i) = self%xcd(i) + c; self%xcd(l) = self%xcd(l) + c
         if (i > 0 .and. l > 0) then
            self%xjo(min(i, l)) = self%xjo(min(i, l)) - val
            self%xco(min(i, l)) = self%xco(min(i, l)) - c
         end if
      end subroutine stencil
   end subroutine others_tangent

   !> Accept the last evaluation: committed ← trial (branches, bilinear states).
   subroutine commit(self)
      class(chain_step_t), intent(inout) :: self
      call swap_int8(self%pbr, self%pbrc); call swap_int8(self%xbr, self%xbrc)
      call swap(self%bfc, self%bft); call swap(self%bdu, self%bdut)
   end subroutine commit

   !> A step the fused sweeps do not settle, taken by the general path from the same
   !> committed state (its chatter rule, line search and failure messages). Its stepper is
   !> made at the first such step (on the model with its chains as links and contacts one by
   !> one: their numbers are those of all the model's items) and handed the committed state
   !> each time: the element states from ours (a contact we hold open has no force), f_ext at
   !> t_n.
   subroutine general_step(self, m, t, o, stat)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      self%factored = .false.
      if (m%nchain > 0) then
         if (.not. allocated(self%gm)) then
            allocate (self%gm, stat=stat)
            if (stat /= 0) then
               call out_of_memory('a copy of the model for the general path of the fused chain step', &
                                  -1.0_dp, FIX_SMALLER_SCENE, stat, o%message)
            else
               call model_expanded(m, self%gm, stat, o%message)
            end if
            if (stat /= MARTELLO_OK) then
               call observer_failed(o, t, stat); return
            end if
            call effective_mass_prepare(self%gm, o%message, stat)
            if (stat /= MARTELLO_OK) return
         end if
         call take(self%gm)
      else
         call take(m)
      end if
   contains
      subroutine take(gm)
         type(model_t), intent(in) :: gm
         integer(i8) :: saved(size(o%counters))
         integer :: idx, j, i
         if (.not. allocated(self%gen)) then
            ! its start at t = 0 (a = M⁻¹(f_ext − f_int)) is overwritten below: not counted
            allocate (self%gen, stat=stat)
            if (stat /= 0) then
               call out_of_memory('the general path of the fused chain step', -1.0_dp, &
                                  FIX_SMALLER_SCENE, stat, o%message)
               call observer_failed(o, t, stat); return
            end if
            saved = o%counters
            call self%gen%init(gm, self%settings, o, stat)
            o%counters = saved
            if (stat /= MARTELLO_OK) return
         end if
         associate (gen => self%gen, ms => self%gen%ms)
            gen%un = self%un; gen%vn = self%vn; gen%an = self%an; gen%t0 = self%t0
            do idx = 1, size(self%blk%blo)
               j = self%blk%blo(idx)
               ms%link_fc(j) = self%bfc(idx); ms%link_u(j) = self%bdu(idx)
            end do
            ms%forced_off = .false.
            call internal_forces(gm, ms, gen%un, gen%vn, gen%fint)
            call mech_commit(gm, ms, gen%un)
            do i = 1, m%n - 1
               if (pair_contact(self, i) > 0) call hold(pair_contact(self, i), self%pbrc(i))
            end do
            do idx = 1, size(self%blk%xc)
               call hold(self%blk%xc(idx), self%xbrc(idx))
            end do
            call external_forces(gm, gen%mrow, self%t0, gen%fext)
            gen%tangent_valid = .false.
            call gen%step(gm, t, o, stat)
            if (stat /= MARTELLO_OK) return
            self%u = gen%u; self%v = gen%v; self%a = gen%a
            do idx = 1, size(self%blk%blo)
               j = self%blk%blo(idx)
               self%bfc(idx) = ms%link_fc(j); self%bdu(idx) = ms%link_u(j)
            end do
            do i = 1, m%n - 1
               if (pair_contact(self, i) > 0) self%pbrc(i) = branch_of(pair_contact(self, i))
            end do
            do idx = 1, size(self%blk%xc)
               self%xbrc(idx) = branch_of(self%blk%xc(idx))
            end do
         end associate
      end subroutine take

      !> contact j committed off here is off there (no force)
      subroutine hold(j, br)
         integer, intent(in) :: j
         integer(int8), intent(in) :: br
         if (br /= BRANCH_OFF) return
         self%gen%ms%con_on(j) = .false.; self%gen%ms%con_f(j) = 0.0_dp
      end subroutine hold

      !> our branch of contact j from the general path's committed state: clipped where the
      !> Kelvin law's cut-off holds its force at 0
      integer(int8) function branch_of(j) result(br)
         integer, intent(in) :: j
         integer :: a, b, scheme, law
         real(dp) :: gap, par(NPAR_CONTACT)
         br = BRANCH_OFF
         if (.not. self%gen%ms%con_on(j)) return
         br = BRANCH_ON
         call model_contact_at(m, j, a, b, gap, scheme, law, par)
         if (law == LAW_KELVIN .and. par(P_CLIP) > 0.5_dp .and. self%gen%ms%con_f(j) == 0.0_dp) &
            br = BRANCH_CLIPPED
      end function branch_of
   end subroutine general_step

   !> The observer's start: the phases of the contacts closed at t = 0 and the energies
   !> there.
   subroutine chain_measure_start(self, m, o, energy_interval, stat)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: energy_interval
      integer, intent(out) :: stat
      integer :: i, idx, j
      do i = 1, self%n - 1
         if (pair_contact(self, i) == 0 .or. self%pbrc(i) == BRANCH_OFF) cycle
         call observer_open_phase(o, pair_contact(self, i), 0.0_dp, &
                                  self%blk%sgn(i*self%blk%ss)*(self%v(i) - self%v(i + 1)))
      end do
      do idx = 1, size(self%blk%xg)
         j = self%blk%xg(idx)
         if (self%xbrc(idx) /= BRANCH_OFF) call observer_open_phase(o, self%blk%xc(idx), 0.0_dp, &
                                                               self%v(m%con_a(j)) - self%v(m%con_b(j)))
      end do
      call observer_begin(o, m, self%ms, self%u, self%v, self%a, energy_interval, self%advice, &
                          0.0_dp, stat, energies=energies(self, m))
      if (stat /= MARTELLO_OK) call observer_failed(o, 0.0_dp, stat)
   end subroutine chain_measure_start

   !> The committed state at t = t_k handed to the observer's bulk entry (observer_block):
   !> the states of the nodes at this sample and the previous one, the committed branches of
   !> the contacts and the committed states of the bilinear links, and where due the energies.
   subroutine chain_measure(self, m, o, t, k, stat)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer(i8), intent(in) :: k
      integer, intent(out) :: stat
      real(dp), allocatable :: e(:)     ! unallocated: not present (the energies are not due)
      if (observer_energy_due(o, k)) e = energies(self, m)
      call observer_block(o, m, t, merge(self%h, 0.0_dp, k > 0), k, self%blk, self%un, self%vn, &
                          self%an, self%u, self%v, self%a, self%pbrc, self%xbrc, self%bfc, &
                          self%bdu, stat, e)
   end subroutine chain_measure

   !> [kinetic, links, contacts] energy of the committed state: ½ vᵀMv, the springs' ½ k Δu²
   !> and the bilinear springs' recoverable energy, the contacts' elastic energy at max(δ, 0)
   !> (as recoverable_energy).
   function energies(self, m) result(e)
      class(chain_step_t), intent(in) :: self
      type(model_t), intent(in) :: m
      real(dp) :: e(3)
      integer :: i, n, idx, j
      real(dp) :: du, pen, eb
      n = self%n
      e = 0.0_dp
      associate (u => self%u, v => self%v)
         do i = 1, n
            e(1) = e(1) + 0.5_dp*m%mass(i)*v(i)*v(i)
            if (self%chain_links) then
               e(2) = e(2) + 0.5_dp*m%chain(1)%k(i)*u(i)*u(i)
            else
               e(2) = e(2) + 0.5_dp*self%kg(i)*u(i)*u(i)
            end if
         end do
         if (self%pair_links) then
            do i = 1, n - 1
               du = u(i) - u(i + 1)
               e(2) = e(2) + 0.5_dp*self%kp(i)*du*du
            end do
         end if
         do idx = 1, size(self%blk%bl)
            j = self%blk%bl(idx)
            call bilinear_energy(m%link_par(L_STIFF, j), m%link_par(L_YIELD, j), &
                                 m%link_par(L_HARDENING, j), self%bfc(idx), self%bdu(idx), eb)
            e(2) = e(2) + eb
         end do
         do i = 1, n - 1
            if (pair_contact(self, i) == 0) cycle
            pen = self%blk%sgn(i*self%blk%ss)*(u(i) - u(i + 1)) - self%blk%gap(i*self%blk%sg)
            if (pen > 0.0_dp) e(3) = e(3) + 0.5_dp*self%blk%k(i*self%blk%sk)*pen*pen
         end do
         do idx = 1, size(self%blk%xg)
            j = self%blk%xg(idx)
            pen = u(m%con_a(j)) - u(m%con_b(j)) - m%con_gap(j)
            e(3) = e(3) + contact_elastic_energy(m%con_law(j), m%con_par(:, j), max(pen, 0.0_dp))
         end do
      end associate
   end function energies

   !> Every pair contact shares its sign, gap, stiffness and law, and every node its mass
   !> (stride 0 for all): the usual [[chain]].
   pure logical function from_chain_of_one_kind(self) result(one)
      class(chain_step_t), intent(in) :: self
      one = self%blk%ss == 0 .and. self%blk%sg == 0 .and. self%blk%sk == 0 .and. self%blk%sc == 0 .and. &
            self%blk%sl == 0 .and. self%sm == 0
   end function from_chain_of_one_kind

   !> The contact of pair (i, i+1) among all the model's contacts (0: none).
   pure integer function pair_contact(self, i) result(c)
      class(chain_step_t), intent(in) :: self
      integer, intent(in) :: i
      if (self%blk%first >= 0) then
         c = 0
         if (i >= 1 .and. i < self%n) c = self%blk%first + i
      else
         c = self%blk%number(i)
      end if
   end function pair_contact

   subroutine swap(x, y)
      real(dp), allocatable, intent(inout) :: x(:), y(:)
      real(dp), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap

   subroutine swap_int8(x, y)
      integer(int8), allocatable, intent(inout) :: x(:), y(:)
      integer(int8), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap_int8
end module martello_chain_step