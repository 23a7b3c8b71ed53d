!> The fused chain step's scene per node (docs/run-layer.md "The fused chain step"): the
!> model's links and contacts, chains whole or items one by one, as the arrays its sweeps
!> read — the linear links summed per node and per pair, the pair contacts' laws in its
!> node_block_t (one value for the chain where every pair shares it), the other elements one
!> by one.
submodule (martello_chain_step) per_node_layout
   implicit none

contains

   !> The chain per node from the model's links and contacts (chain_fusable holds): the
   !> linear links summed per node and per pair, the first contact of each pair in the pair
   !> arrays (one value for the chain where all pairs share it), the rest one by one.
   !> st > 0: an allocation failed (the state is then incomplete).
   module subroutine per_node(self, m, st)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer :: n, j, a, b, lo, nb, nx, q, i, c
      real(dp) :: k, cd
      logical, allocatable :: pair(:)
      n = m%n
      self%chain_links = m%nchain == 1 .and. m%nlink == 0
      if (self%chain_links) self%chain_links = m%chain(1)%first == 1 .and. m%chain(1)%n == n .and. &
                                               allocated(m%chain(1)%c)
      allocate (self%kg(merge(0, n, self%chain_links)), self%cg(merge(0, n, self%chain_links)), &
                self%blk%number(0:n), pair(m%ncontact), self%pbr(0:n), self%pbrc(0:n), self%pbrf(0:n), &
                stat=st)
      if (st /= 0) return
      self%kg = 0.0_dp; self%cg = 0.0_dp
      self%pair_links = .false.
      do j = 1, m%nlink
         a = m%link_a(j); b = m%link_b(j)
         if (m%link_kind(j) /= LINK_BILINEAR .and. a > 0 .and. b > 0) self%pair_links = .true.
      end do
      ! unused ones hold one entry: the kernels take them as arrays
      allocate (self%kp(0:merge(n, 0, self%pair_links)), self%cp(0:merge(n, 0, self%pair_links)), &
                stat=st)
      if (st /= 0) return
      self%kp = 0.0_dp; self%cp = 0.0_dp
      nb = 0
      do j = 1, m%nlink
         a = m%link_a(j); b = m%link_b(j)
         k = 0.0_dp; cd = 0.0_dp
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR)
            k = m%link_par(L_STIFF, j)
         case (LINK_DASHPOT)
            cd = m%link_par(L_DAMP, j)
         case default
            nb = nb + 1; cycle
         end select
         if (a > 0 .and. b > 0) then
            lo = min(a, b)
            self%kp(lo) = self%kp(lo) + k; self%cp(lo) = self%cp(lo) + cd
         else
            self%kg(a + b) = self%kg(a + b) + k; self%cg(a + b) = self%cg(a + b) + cd
         end if
      end do
      ! the chains' springs and dashpots (chain_fusable: linear)
      do q = merge(m%nchain + 1, 1, self%chain_links), m%nchain
         associate (ch => m%chain(q))
            do i = 1, ch%n
               j = ch%first + i - 1
               self%kg(j) = self%kg(j) + ch%k(i)
               if (allocated(ch%c)) self%cg(j) = self%cg(j) + ch%c(i)
            end do
         end associate
      end do
      self%blk%bl = pack([(j, j = 1, m%nlink)], m%link_kind(1:m%nlink) == LINK_BILINEAR)
      self%blk%blo = [(model_link_index(m, self%blk%bl(j)), j = 1, nb)]
      allocate (self%bfc(nb), self%bdu(nb), self%bft(nb), self%bdut(nb), self%bbr(nb), &
                self%bbrf(nb), stat=st)
      if (st /= 0) return
      self%bbr = B_ELASTIC; self%bbrf = B_ELASTIC
      ! the pair contacts: the chains' (chain_fusable: one to a pair), then the first contact
      ! added one by one between i and i + 1; numbered among all the model's contacts
      self%blk%number = 0; pair = .false.
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            do i = 1, ch%ncontact
               self%blk%number(ch%first + i - 1) = ch%contact0 + i
            end do
         end associate
      end do
      do j = 1, m%ncontact
         a = m%con_a(j); b = m%con_b(j)
         if (a == 0 .or. b == 0) cycle
         lo = min(a, b)
         if (self%blk%number(lo) == 0) then
            self%blk%number(lo) = model_contact_index(m, j); pair(j) = .true.
         end if
      end do
      self%blk%pairs = any(self%blk%number > 0)
      call pair_parameters(self, m, st)
      if (st /= 0) return
      if (n > 1) then
         c = self%blk%number(1)
         if (c > 0 .and. all(self%blk%number(1:n - 1) == [(c - 1 + j, j = 1, n - 1)])) self%blk%first = c - 1
      end if
      if (self%blk%first >= 0) then
         deallocate (self%blk%number); allocate (self%blk%number(0:0), stat=st); self%blk%number = 0
      end if
      self%pbr = BRANCH_OFF; self%pbrc = BRANCH_OFF; self%pbrf = BRANCH_OFF
      self%blk%xg = pack([(j, j = 1, m%ncontact)], .not. pair)
      nx = size(self%blk%xg)
      self%blk%xc = [(model_contact_index(m, self%blk%xg(j)), j = 1, nx)]
      allocate (self%xbr(nx), self%xbrc(nx), self%xbrf(nx), stat=st)
      if (st /= 0) return
      self%xbr = BRANCH_OFF; self%xbrc = BRANCH_OFF; self%xbrf = BRANCH_OFF
      self%others = nb > 0 .or. nx > 0
      nx = merge(n, 0, self%others)
      allocate (self%xjd(0:nx), self%xjo(0:nx), self%xcd(0:nx), self%xco(0:nx), stat=st)
      if (st /= 0) return
      self%xjd = 0.0_dp; self%xjo = 0.0_dp; self%xcd = 0.0_dp; self%xco = 0.0_dp
   end subroutine per_node

   !> The pair contacts' parameters: sign, gap, stiffness, damping and law, each one value for
   !> the chain (stride 0) where every pair has a contact and they share it.
   subroutine pair_parameters(self, m, st)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer :: n, i, j, a, b, scheme, claw
      real(dp), allocatable :: sgn(:), gap(:), k(:), c(:)
      real(dp) :: par(NPAR_CONTACT), mstar
      integer(int8), allocatable :: law(:)
      logical :: every
      n = m%n
      allocate (sgn(0:n), gap(0:n), k(0:n), c(0:n), law(0:n), stat=st)
      if (st /= 0) return
      ! a pair without a contact: a gap no motion closes
      sgn = 1.0_dp; gap = huge(1.0_dp); k = 0.0_dp; c = 0.0_dp; law = AFFINE_LINEAR
      do i = 1, n - 1
         j = self%blk%number(i)
         if (j == 0) cycle
         call model_contact_at(m, j, a, b, gap(i), scheme, claw, par)
         sgn(i) = merge(1.0_dp, -1.0_dp, a == i)
         k(i) = par(P_STIFF)
         if (claw == LAW_KELVIN) then
            ! the damping of a target restitution, with the pair's m* (as
            ! effective_mass_prepare gives the contacts added one by one)
            c(i) = par(P_DAMPING)
            if (par(P_RESTITUTION) >= 0.0_dp) then
               mstar = pair_effective_mass(m, a, b)
               c(i) = 0.0_dp
               if (ieee_is_finite(mstar)) c(i) = damping_from_restitution(claw, &
                                                                          par(P_RESTITUTION), par, mstar)
            end if
            law(i) = merge(AFFINE_KELVIN_CLIPPED, AFFINE_KELVIN, par(P_CLIP) > 0.5_dp)
         end if
      end do
      self%blk%kelvin = any(law(1:n - 1) /= AFFINE_LINEAR)
      every = n > 1 .and. all(self%blk%number(1:n - 1) > 0)
      call one_or_all(sgn, self%blk%sgn, self%blk%ss)
      if (st == 0) call one_or_all(gap, self%blk%gap, self%blk%sg)
      if (st == 0) call one_or_all(k, self%blk%k, self%blk%sk)
      if (st == 0) call one_or_all(c, self%blk%c, self%blk%sc)
      if (st /= 0) return
      if (every .and. all(law(1:n - 1) == law(1))) then
         allocate (self%blk%law(0:0), stat=st); self%blk%law(0) = law(1); self%blk%sl = 0
      else
         call move_alloc(law, self%blk%law); self%blk%sl = 1
      end if
   contains
      !> x(0:n) as one value at index 0 (stride 0) if pairs 1 … n−1 all have a contact and
      !> share it, else whole (stride 1).
      subroutine one_or_all(x, to, stride)
         real(dp), allocatable, intent(inout) :: x(:)
         real(dp), allocatable, intent(out) :: to(:)
         integer, intent(out) :: stride
         if (every .and. all(x(1:n - 1) == x(1))) then
            allocate (to(0:0), stat=st); if (st /= 0) return
            to(0) = x(1); stride = 0
         else
            allocate (to(0:n), stat=st); if (st /= 0) return
            to(0:n) = x; stride = 1
         end if
      end subroutine one_or_all
   end subroutine pair_parameters
end submodule per_node_layout
