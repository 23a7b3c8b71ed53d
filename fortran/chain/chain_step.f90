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
      model_initial_state, model_contact_index, model_contact_at, model_expanded, &
      model_has_influence
   use martello_element_rows, only: row_a, row_b, row_is_pair
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP, &
      L_YIELD, L_HARDENING, bilinear_return_map, bilinear_energy
   use martello_contact_laws, only: LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING, P_CLIP, &
      P_RESTITUTION, NPAR_CONTACT, contact_elastic_energy, damping_from_restitution, BRANCH_OFF, &
      BRANCH_ON, BRANCH_CLIPPED, AFFINE_LINEAR, AFFINE_KELVIN, AFFINE_KELVIN_CLIPPED
   use martello_effective_mass, only: pair_effective_mass, effective_mass_prepare
   use martello_assembly, only: external_forces, uniform_acceleration, internal_forces, mech_commit, &
      swap
   use martello_time_functions, only: tf_value
   use martello_observer, only: observer_t, node_block_t, observer_fail, observer_failed, &
      observer_work, observer_begin, observer_block, observer_open_phase, observer_energy_due
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS, C_FUSED
   use martello_integrator_settings, only: integrator_settings_t, INT_NEWMARK
   use martello_fixed_step, only: stepper_t
   use martello_generalized_alpha, only: generalized_alpha_t
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
      !> the per-node arrays in one block, each x(i) at store(ox + i): u, v, a, their values
      !> at the step's start un, vn, an and fe (below) on nodes 0:n, the reciprocal pivots rp
      !> and the summed linear links of a node to ground kg, cg on 1:n (no entries where the
      !> chain's are read, chain_links); each one's first entries on L1 sets of their own,
      !> whatever malloc gives (layout, fortran/chain/per_node.f90)
      real(dp), allocatable :: store(:)
      integer :: ou = 0, ov = 0, oa = 0, oun = 0, ovn = 0, oan = 0, ofe = 0, orp = 0, okg = 0, &
                 ocg = 0
      !> the linear links of the pair (i, i+1) summed (kp, cp, 0:n with 0 and n zero;
      !> allocated if any)
      real(dp), allocatable :: kp(:), cp(:)
      logical :: pair_links = .false.
      !> the links are those of the model's one chain on every node, dashpots included: kg and
      !> cg are its k and c, read there (no copy, no entries in store)
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
      !> internal force again: one array for both (rp and fe in store)
      real(dp), allocatable :: fnod(:)
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
      procedure :: from_chain_of_one_kind, pair_contact
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
      !> The other elements at the iterate, one by one (fortran/chain/one_by_one.f90): forces,
      !> branches, works; and their tangents on their branches, per node.
      module subroutine others(self, m, flipped)
         class(chain_step_t), intent(inout) :: self
         type(model_t), intent(in) :: m
         logical, intent(inout) :: flipped
      end subroutine others
      module subroutine others_tangent(self, m)
         class(chain_step_t), intent(inout) :: self
         type(model_t), intent(in) :: m
      end subroutine others_tangent
      !> A step the fused sweeps do not settle, by the general path (fortran/chain/general_path.f90).
      module subroutine general_step(self, m, t, o, stat)
         class(chain_step_t), intent(inout) :: self
         type(model_t), intent(in) :: m
         real(dp), intent(in) :: t
         type(observer_t), intent(inout) :: o
         integer, intent(out) :: stat
      end subroutine general_step
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
      ok = model_bandwidth(m) <= 1 .and. m%ncoupling == 0 .and. m%nblock == 0 &
           .and. .not. model_has_influence(m)     ! the sweep loads every node with its mass
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR)
         case default
            ok = .false.
         end select
         if (.not. row_is_pair(m%lnk, j)) ok = .false.   ! the sweep takes node pairs
      end do
      do j = 1, m%ncontact
         if (.not. row_is_pair(m%con, j)) ok = .false.
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
      integer :: n, i, j, st
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
                self%pen(0), self%force(0), self%fnod(m%nforce), stat=st)
      if (st == 0) call per_node(self, m, st)
      if (st /= 0) then
         write (num, '(i0)') n
         call out_of_memory('the per-node state of the fused chain step for '//trim(num)//' nodes', &
                            -1.0_dp, FIX_SMALLER_SCENE, stat, msg)
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%mass = m%mass(1:size(self%mass))
      associate (x => self%store)
         x(self%ou) = 0.0_dp; x(self%ov) = 0.0_dp
         call model_initial_state(m, x(self%ou + 1:self%ou + n), x(self%ov + 1:self%ov + n))
         ! the fixed nodes, listed (no array of every node made for it)
         j = 0
         do i = 1, n
            if (.not. m%fixed(i)) cycle
            j = j + 1; self%fixed_nodes(j) = i
         end do
         ! the bilinear springs start elastic, on k·Δu₀ (clamped into the band by the first
         ! step), as mech_init
         do i = 1, size(self%blk%bl)
            self%bdu(i) = x(self%ou + row_a(m%lnk, self%blk%bl(i))) - x(self%ou + row_b(m%lnk, self%blk%bl(i)))
            self%bfc(i) = m%link_par(L_STIFF, self%blk%bl(i))*self%bdu(i)
         end do
         x(self%orp + 1:self%orp + n) = 0.0_dp; x(self%ofe:self%ofe + n) = 0.0_dp
         self%fnod = 0.0_dp
         self%any_fixed = size(self%fixed_nodes) > 0
         ! the elements at (u0, v0) with their whole laws: the evaluation at an iterate with no
         ! increment, works from (u0, v0) itself
         x(self%oun:self%oun + n) = x(self%ou:self%ou + n); x(self%ovn:self%ovn + n) = x(self%ov:self%ov + n)
         x(self%oa:self%oa + n) = 0.0_dp; x(self%oan:self%oan + n) = 0.0_dp
         self%acc = uniform_acceleration(m, 0.0_dp)
         call evaluate(self, m, .false., flipped)
         call nodal_forces(self, m, 0.0_dp)
         ! M a = f_ext − f_int on the free nodes: M is diagonal (counted as the general path's
         ! factorisation of M)
         do i = 1, n
            x(self%oa + i) = 0.0_dp
            if (.not. m%fixed(i)) x(self%oa + i) = (m%mass(i)*self%acc - x(self%ofe + i))/m%mass(i)
         end do
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         call commit(self)
         x(self%oun:self%oun + n) = x(self%ou:self%ou + n); x(self%ovn:self%ovn + n) = x(self%ov:self%ov + n)
         x(self%oan:self%oan + n) = x(self%oa:self%oa + n)
      end associate
      self%factored = .false.
   end subroutine chain_init

   !> The forward sweep of the first iterate (linearised_sweep) on explicit-shape arrays (no
   !> descriptors, no aliasing: the compiler keeps everything in registers but the arrays);
   !> forward_usual is the same sweep (forward_sweep.inc) with the usual chain's flags and
   !> strides as constants.
   subroutine forward_kernel(n, h, gm, c1, c2, cv, acc, pl, kel, oth, pcs, fx, sk, sc, vn, an, &
                             sm, mass, fe, rp, cg, kp, cp, pk, pc, brf, xcd, xco, xjo, fixed)
      integer, intent(in), value :: n, sk, sc, sm
      real(dp), intent(in), value :: h, gm, c1, c2, cv, acc
      logical, intent(in), value :: pl, kel, oth, pcs, fx
      include 'forward_sweep.inc'
   end subroutine forward_kernel

   subroutine forward_usual(n, h, gm, c1, c2, cv, acc, vn, an, mass, fe, rp, cg, kp, cp, pk, pc, &
                            brf, xcd, xco, xjo, fixed)
      integer, intent(in), value :: n
      real(dp), intent(in), value :: h, gm, c1, c2, cv, acc
      logical, parameter :: pl = .false., kel = .false., oth = .false., pcs = .true., fx = .false.
      integer, parameter :: sk = 0, sc = 0, sm = 0
      include 'forward_sweep.inc'
   end subroutine forward_usual

   !> The forward sweep after a branch change (martello_chain_step refactor_sweep): J on the
   !> current branches factorised, the residual forward-substituted; ok = .false. on a pivot
   !> that is not > 0.
   subroutine refactor_kernel(n, cm, cv, acc, pl, pcs, oth, sk, sc, a, sm, mass, fixed, fe, kg, &
                              cg, kp, cp, pk, pc, br, xjd, xjo, rp, ok)
      integer, intent(in) :: n, sk, sc, sm
      real(dp), intent(in) :: cm, cv, acc
      logical, intent(in) :: pl, pcs, oth, fixed(n)
      real(dp), intent(in) :: a(0:n), mass(*), kg(n), cg(n), kp(0:*), cp(0:*), pk(0:*), pc(0:*), &
                              xjd(0:*), xjo(0:*)
      real(dp), intent(inout) :: fe(0:n)     !< in: the internal force at the iterate; out: y
      integer(int8), intent(in) :: br(0:n)
      real(dp), intent(out) :: rp(n)
      logical, intent(out) :: ok
      integer :: i
      real(dp) :: p, jd, jo, jom, tp, tpm, ym, gm
      ok = .true.
      tpm = 0.0_dp; gm = 0.0_dp; ym = 0.0_dp; jom = 0.0_dp
      do i = 1, n
         ! tp: the tangent of pair (i, i+1), K_t + c_v C_t
         tp = 0.0_dp
         if (i < n) then
            if (pl) tp = kp(i) + cv*cp(i)
            if (pcs) then
               if (br(i) == BRANCH_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
            end if
         end if
         jd = kg(i) + cv*cg(i) + tpm + tp
         if (oth) jd = jd + xjd(i)
         ! J(i, i+1) as the sweeps compute it again (coupling)
         jo = 0.0_dp
         if (i < n) jo = coupling(i, cv, pl, pcs, oth, .true., sk, sc, kp, cp, pk, pc, br, xjo, fixed)
         if (fixed(i)) then
            p = 1.0_dp
         else
            p = cm*mass(1 + (i - 1)*sm) + jd - jom*gm
         end if
         if (.not. (p > 0.0_dp)) ok = .false.
         rp(i) = 1.0_dp/p
         if (fixed(i)) then
            ym = 0.0_dp
         else
            ym = mass(1 + (i - 1)*sm)*(acc - a(i)) - fe(i) - gm*ym
         end if
         gm = jo*rp(i)
         fe(i) = ym
         tpm = tp; jom = jo
      end do
      fe(0) = 0.0_dp
   end subroutine refactor_kernel

   !> J(i, i+1), i < n, of the factors made on the branches brf: −(K_t + c_v C_t) of the pair
   !> (i, i+1) (its summed links, its contact where on), plus the other elements' (xjo), 0 at
   !> a fixed row or column (fx: some node is fixed). L(i+1, i) = J(i, i+1)·rp(i): the sweeps
   !> compute it again from the branch bytes rather than read it from an array (8 B per node
   !> less to keep, and to stream at every step), to the same bits as the factorisation.
   pure real(dp) function coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, brf, xjo, &
                                   fixed) result(jo)
      integer, intent(in) :: i, sk, sc
      real(dp), intent(in) :: cv, kp(0:*), cp(0:*), pk(0:*), pc(0:*), xjo(0:*)
      logical, intent(in) :: pl, pcs, oth, fx, fixed(*)
      integer(int8), intent(in) :: brf(0:*)
      real(dp) :: tp
      tp = 0.0_dp
      if (pl) tp = kp(i) + cv*cp(i)
      if (pcs) then
         if (brf(i) == BRANCH_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
      end if
      jo = -tp
      if (oth) jo = jo + xjo(i)
      if (fx) then
         if (fixed(i) .or. fixed(i + 1)) jo = 0.0_dp
      end if
   end function coupling

   !> The backward sweep and the elements at the new iterate (evaluate) on explicit-shape
   !> arrays (no descriptors, no aliasing). The parameter arrays of the pair contacts are read
   !> at i·stride (stride 0: one value for the chain). back_usual_start and back_usual_iterate
   !> are the same sweep (back_sweep.inc) with the usual chain's flags and strides, and from
   !> where it starts, as constants.
   subroutine back_kernel(n, from_start, pl, pcs, kel, oth, fx, ss, sg, sk, sc, sl, cm, cv, c1, &
                          c2, h, gm, rp, u, v, a, un, vn, an, sm, mass, fe, kg, cg, kp, cp, psgn, &
                          pgap, pk, pc, plaw, pbr, pbrc, pbrf, xjo, fixed, mdu, wd, wl, wc, flip)
      integer, intent(in), value :: n, ss, sg, sk, sc, sl, sm
      logical, intent(in), value :: from_start, pl, pcs, kel, oth, fx
      real(dp), intent(in), value :: cm, cv, c1, c2, h, gm
      include 'back_sweep.inc'
   end subroutine back_kernel

   subroutine back_usual_start(n, cm, cv, c1, c2, h, gm, rp, u, v, a, un, vn, an, mass, fe, kg, &
                               cg, kp, cp, psgn, pgap, pk, pc, plaw, pbr, pbrc, pbrf, xjo, fixed, &
                               mdu, wd, wl, wc, flip)
      logical, parameter :: from_start = .true.
      include 'back_usual.inc'
   end subroutine back_usual_start

   subroutine back_usual_iterate(n, cm, cv, c1, c2, h, gm, rp, u, v, a, un, vn, an, mass, fe, kg, &
                                 cg, kp, cp, psgn, pgap, pk, pc, plaw, pbr, pbrc, pbrf, xjo, fixed, &
                                 mdu, wd, wl, wc, flip)
      logical, parameter :: from_start = .false.
      include 'back_usual.inc'
   end subroutine back_usual_iterate

   !> The committed state becomes the start of the next step by swapping the buffers: the
   !> step writes every entry of u, v, a before reading it.
   subroutine chain_begin_step(self)
      class(chain_step_t), intent(inout) :: self
      call swap_at(self%ou, self%oun); call swap_at(self%ov, self%ovn); call swap_at(self%oa, self%oan)
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
         self%store(self%orp + 1:self%orp + self%n) = 0.0_dp
         self%store(self%ofe:self%ofe + self%n) = 0.0_dp
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
         w_ext = w_ext + 0.5_dp*(f + self%fnod(j))*(self%store(self%ou + i) - self%store(self%oun + i))
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
         self%store(self%ofe + m%force_node(j)) = self%store(self%ofe + m%force_node(j)) + &
                                                  self%fnod(j) - f
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
      integer :: n
      n = self%n
      associate (x => self%store)
         if (self%chain_links) then
            call sweep(m%chain(1)%c)
         else
            call sweep(x(self%ocg + 1:self%ocg + n))
         end if
      end associate
      call pin_fixed(self)
   contains
      subroutine sweep(cg)
         real(dp), intent(in), contiguous :: cg(:)
         associate (x => self%store)
            if (.not. (self%pair_links .or. self%blk%kelvin .or. self%others) .and. &
                self%blk%pairs .and. self%from_chain_of_one_kind()) then
               ! the usual chain: its kernel with these as constants (evaluate says why)
               call forward_usual(n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                  x(self%ovn:self%ovn + n), x(self%oan:self%oan + n), self%mass, &
                                  x(self%ofe:self%ofe + n), x(self%orp + 1:self%orp + n), cg, self%kp, &
                                  self%cp, self%blk%k, self%blk%c, self%pbrf, self%xcd, self%xco, &
                                  self%xjo, m%fixed)
            else
               call forward_kernel(n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                   self%pair_links, self%blk%kelvin, self%others, self%blk%pairs, &
                                   self%any_fixed, self%blk%sk, self%blk%sc, x(self%ovn:self%ovn + n), &
                                   x(self%oan:self%oan + n), self%sm, self%mass, &
                                   x(self%ofe:self%ofe + n), x(self%orp + 1:self%orp + n), cg, self%kp, &
                                   self%cp, self%blk%k, self%blk%c, self%pbrf, self%xcd, self%xco, &
                                   self%xjo, m%fixed)
            end if
         end associate
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
      integer :: n
      n = self%n
      if (self%others) call others_tangent(self, m)
      self%pbrf = self%pbr; self%bbrf = self%bbr; self%xbrf = self%xbr
      o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      associate (x => self%store)
         if (self%chain_links) then
            call sweep(m%chain(1)%k, m%chain(1)%c)
         else
            call sweep(x(self%okg + 1:self%okg + n), x(self%ocg + 1:self%ocg + n))
         end if
      end associate
      self%factored = ok
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         associate (x => self%store)
            call refactor_kernel(n, self%cm, self%cv, self%acc, self%pair_links, self%blk%pairs, &
                                 self%others, self%blk%sk, self%blk%sc, x(self%oa:self%oa + n), &
                                 self%sm, self%mass, m%fixed, x(self%ofe:self%ofe + n), kg, cg, &
                                 self%kp, self%cp, self%blk%k, self%blk%c, self%pbr, self%xjd, &
                                 self%xjo, x(self%orp + 1:self%orp + n), ok)
         end associate
      end subroutine sweep
   end subroutine refactor_sweep

   !> Fixed rows carry no residual: their Δu is 0 (their column of the factors is 0, so no
   !> other row depends on their entry of y).
   subroutine pin_fixed(self)
      class(chain_step_t), intent(inout) :: self
      integer :: k
      do k = 1, size(self%fixed_nodes)
         self%store(self%ofe + self%fixed_nodes(k)) = 0.0_dp
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
      integer :: n
      n = self%n
      associate (x => self%store)
         if (self%chain_links) then
            call sweep(m%chain(1)%k, m%chain(1)%c)
         else
            call sweep(x(self%okg + 1:self%okg + n), x(self%ocg + 1:self%ocg + n))
         end if
      end associate
      self%mdu = self%mdu + mdu
      if (self%others) call others(self, m, flipped)
      self%fnod = 0.0_dp
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         associate (x => self%store)
            if (.not. (self%pair_links .or. self%blk%kelvin) .and. self%blk%pairs .and. &
                self%from_chain_of_one_kind()) then
               ! the usual chain (springs and dashpots to ground, one linear contact law and gap
               ! for every pair, one mass): its kernels, with these and where the sweep starts as
               ! constants the compiler folds (no branches on them, the parameters read once)
               if (from_start) then
                  call back_usual_start(n, self%cm, self%cv, self%c1, self%c2, self%h, self%gamma, &
                                        x(self%orp + 1:self%orp + n), x(self%ou:self%ou + n), &
                                        x(self%ov:self%ov + n), x(self%oa:self%oa + n), &
                                        x(self%oun:self%oun + n), x(self%ovn:self%ovn + n), &
                                        x(self%oan:self%oan + n), self%mass, x(self%ofe:self%ofe + n), &
                                        kg, cg, self%kp, self%cp, self%blk%sgn, self%blk%gap, &
                                        self%blk%k, self%blk%c, self%blk%law, self%pbr, self%pbrc, &
                                        self%pbrf, self%xjo, m%fixed, mdu, self%wd, self%wl, &
                                        self%wc, flipped)
               else
                  call back_usual_iterate(n, self%cm, self%cv, self%c1, self%c2, self%h, &
                                          self%gamma, x(self%orp + 1:self%orp + n), &
                                          x(self%ou:self%ou + n), x(self%ov:self%ov + n), &
                                          x(self%oa:self%oa + n), x(self%oun:self%oun + n), &
                                          x(self%ovn:self%ovn + n), x(self%oan:self%oan + n), &
                                          self%mass, x(self%ofe:self%ofe + n), kg, cg, self%kp, &
                                          self%cp, self%blk%sgn, self%blk%gap, self%blk%k, &
                                          self%blk%c, self%blk%law, self%pbr, self%pbrc, self%pbrf, &
                                          self%xjo, m%fixed, mdu, self%wd, self%wl, self%wc, flipped)
               end if
            else
               call back_kernel(n, from_start, self%pair_links, self%blk%pairs, self%blk%kelvin, &
                                self%others, self%any_fixed, self%blk%ss, self%blk%sg, self%blk%sk, &
                                self%blk%sc, self%blk%sl, self%cm, self%cv, self%c1, self%c2, self%h, &
                                self%gamma, x(self%orp + 1:self%orp + n), x(self%ou:self%ou + n), &
                                x(self%ov:self%ov + n), x(self%oa:self%oa + n), &
                                x(self%oun:self%oun + n), x(self%ovn:self%ovn + n), &
                                x(self%oan:self%oan + n), self%sm, self%mass, &
                                x(self%ofe:self%ofe + n), kg, cg, self%kp, self%cp, self%blk%sgn, &
                                self%blk%gap, self%blk%k, self%blk%c, self%blk%law, self%pbr, &
                                self%pbrc, self%pbrf, self%xjo, m%fixed, mdu, self%wd, self%wl, &
                                self%wc, flipped)
            end if
         end associate
      end subroutine sweep
   end subroutine evaluate


   !> Accept the last evaluation: committed ← trial (branches, bilinear states).
   subroutine commit(self)
      class(chain_step_t), intent(inout) :: self
      call swap_int8(self%pbr, self%pbrc); call swap_int8(self%xbr, self%xbrc)
      call swap(self%bfc, self%bft); call swap(self%bdu, self%bdut)
   end subroutine commit


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
         if (self%pair_contact(i) == 0 .or. self%pbrc(i) == BRANCH_OFF) cycle
         call observer_open_phase(o, self%pair_contact(i), 0.0_dp, &
                                  self%blk%sgn(i*self%blk%ss)*(self%store(self%ov + i) - &
                                                                self%store(self%ov + i + 1)))
      end do
      do idx = 1, size(self%blk%xg)
         j = self%blk%xg(idx)
         if (self%xbrc(idx) /= BRANCH_OFF) call observer_open_phase(o, self%blk%xc(idx), 0.0_dp, &
                                                               self%store(self%ov + row_a(m%con, j)) - &
                                                               self%store(self%ov + row_b(m%con, j)))
      end do
      call observer_begin(o, m, self%ms, self%store(self%ou:self%ou + self%n), &
                          self%store(self%ov:self%ov + self%n), self%store(self%oa:self%oa + self%n), &
                          energy_interval, self%advice, &
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
      associate (x => self%store, n => self%n)
         call observer_block(o, m, t, merge(self%h, 0.0_dp, k > 0), k, self%blk, &
                             x(self%oun:self%oun + n), x(self%ovn:self%ovn + n), &
                             x(self%oan:self%oan + n), x(self%ou:self%ou + n), x(self%ov:self%ov + n), &
                             x(self%oa:self%oa + n), self%pbrc, self%xbrc, self%bfc, self%bdu, stat, e)
      end associate
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
      call of_state(self%store(self%ou:self%ou + n), self%store(self%ov:self%ov + n))
   contains
      subroutine of_state(u, v)
         real(dp), intent(in) :: u(0:n), v(0:n)
         if (self%chain_links) then
            call of_nodes(u, v, m%mass, m%chain(1)%k)
         else
            call of_nodes(u, v, m%mass, self%store(self%okg + 1:self%okg + n))
         end if
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
         associate (b => self%blk)
            do i = 1, merge(n - 1, 0, b%pairs)
               if (b%first < 0) then
                  if (b%number(i) == 0) cycle
               end if
               pen = b%sgn(i*b%ss)*(u(i) - u(i + 1)) - b%gap(i*b%sg)
               if (pen > 0.0_dp) e(3) = e(3) + 0.5_dp*b%k(i*b%sk)*pen*pen
            end do
         end associate
         do idx = 1, size(self%blk%xg)
            j = self%blk%xg(idx)
            pen = u(row_a(m%con, j)) - u(row_b(m%con, j)) - m%con_gap(j)
            e(3) = e(3) + contact_elastic_energy(m%con_law(j), m%con_par(:, j), max(pen, 0.0_dp))
         end do
      end subroutine of_state
      !> ½ Σ m v² and ½ Σ k u² of the springs to ground, on explicit-shape arrays (the
      !> compiler keeps the sums in registers)
      subroutine of_nodes(u, v, mass, kg)
         real(dp), intent(in) :: u(0:n), v(0:n), mass(n), kg(n)
         real(dp) :: ek, ep
         ek = e(1); ep = e(2)
         do i = 1, n
            ek = ek + 0.5_dp*mass(i)*v(i)*v(i)
            ep = ep + 0.5_dp*kg(i)*u(i)*u(i)
         end do
         e(1) = ek; e(2) = ep
      end subroutine of_nodes
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

   !> x ↔ y (two arrays' offsets in store)
   subroutine swap_at(x, y)
      integer, intent(inout) :: x, y
      integer :: tmp
      tmp = x; x = y; y = tmp
   end subroutine swap_at

   subroutine swap_int8(x, y)
      integer(int8), allocatable, intent(inout) :: x(:), y(:)
      integer(int8), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap_int8
end module martello_chain_step