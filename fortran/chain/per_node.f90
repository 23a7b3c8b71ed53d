!> The fused chain step's scene per node (docs/run-layer.md "The fused chain step"): the
!> model's links and contacts, chains whole or items one by one, as the arrays its sweeps
!> read — the linear links summed per node and per pair, the pair contacts' laws in its
!> node_block_t (one value for the chain where every pair shares it), the other elements one
!> by one.
submodule (martello_chain_step) per_node_layout
   use, intrinsic :: iso_c_binding, only: c_loc, c_intptr_t
   implicit none

   !> The L1 data cache's way size (bytes: its sets repeat every page of 4 kB on the x86-64 and
   !> ARM cores of today, 32 kB 8-way or 48 kB 12-way) and the slots of it the arrays of store
   !> start in, one each
   integer, parameter :: WAY = 4096, SLOTS = 16

contains

   !> The chain per node from the model's links and contacts (chain_fusable holds): the
   !> linear links summed per node and per pair, the first contact of each pair in the pair
   !> arrays (one value for the chain where all pairs share it), the rest one by one.
   !> st > 0: an allocation failed (the state is then incomplete).
   module procedure per_node
      integer :: n, j, a, b, lo, nb, nx, q, i, c
      real(dp) :: k, cd
      logical, allocatable :: pair(:)
      n = m%n
      self%chain_links = m%nchain == 1 .and. m%nlink == 0
      if (self%chain_links) self%chain_links = m%chain(1)%first == 1 .and. m%chain(1)%n == n .and. &
                                               allocated(m%chain(1)%c)
      call layout(self, m, st)
      if (st /= 0) return
      allocate (pair(m%ncontact), self%pbr(0:n), self%pbrc(0:n), self%pbrf(0:n), stat=st)
      if (st /= 0) return
      self%pair_links = .false.
      do j = 1, m%nlink
         a = row_a(m%lnk, j); b = row_b(m%lnk, j)
         if (m%link_kind(j) /= LINK_BILINEAR .and. a > 0 .and. b > 0) self%pair_links = .true.
      end do
      ! unused ones hold one entry: the kernels take them as arrays
      allocate (self%kp(0:merge(n, 0, self%pair_links)), self%cp(0:merge(n, 0, self%pair_links)), &
                stat=st)
      if (st /= 0) return
      self%kp = 0.0_dp; self%cp = 0.0_dp
      nb = 0
      do j = 1, m%nlink
         a = row_a(m%lnk, j); b = row_b(m%lnk, j)
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
            associate (kg => self%store(self%okg + a + b), cg => self%store(self%ocg + a + b))
               kg = kg + k; cg = cg + cd
            end associate
         end if
      end do
      ! the chains' springs and dashpots (chain_fusable: linear)
      do q = merge(m%nchain + 1, 1, self%chain_links), m%nchain
         associate (ch => m%chain(q))
            do i = 1, ch%n
               j = ch%first + i - 1
               self%store(self%okg + j) = self%store(self%okg + j) + ch%k(i)
               if (allocated(ch%c)) self%store(self%ocg + j) = self%store(self%ocg + j) + ch%c(i)
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
      ! added one by one between i and i + 1; numbered among all the model's contacts. One
      ! chain over every node and nothing else: pair i has contact contact0 + i (no list made)
      pair = .false.
      if (n > 1 .and. m%nchain == 1 .and. m%ncontact == 0) then
         if (m%chain(1)%first == 1 .and. m%chain(1)%n == n .and. m%chain(1)%ncontact == n - 1) &
            self%blk%first = m%chain(1)%contact0
      end if
      if (self%blk%first < 0) then
         allocate (self%blk%number(0:n), stat=st)
         if (st /= 0) return
         call number_pairs()
      else
         allocate (self%blk%number(0:0), stat=st)
         if (st /= 0) return
         self%blk%number = 0
      end if
      self%blk%pairs = self%blk%first >= 0 .or. any(self%blk%number > 0)
      call pair_parameters(self, m, st)
      if (st /= 0) return
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
   contains
      !> blk%number of every pair from the chains and the contacts added one by one; a list
      !> numbered in order becomes first
      subroutine number_pairs()
         self%blk%number = 0
         do q = 1, m%nchain
            associate (ch => m%chain(q))
               do i = 1, ch%ncontact
                  self%blk%number(ch%first + i - 1) = ch%contact0 + i
               end do
            end associate
         end do
         do j = 1, m%ncontact
            a = row_a(m%con, j); b = row_b(m%con, j)
            if (a == 0 .or. b == 0) cycle
            lo = min(a, b)
            if (self%blk%number(lo) == 0) then
               self%blk%number(lo) = model_contact_index(m, j); pair(j) = .true.
            end if
         end do
         if (n > 1) then
            c = self%blk%number(1)
            if (c > 0 .and. all(self%blk%number(1:n - 1) == [(c - 1 + j, j = 1, n - 1)])) then
               self%blk%first = c - 1
               deallocate (self%blk%number); allocate (self%blk%number(0:0), stat=st)
               if (st == 0) self%blk%number = 0
            end if
         end if
      end subroutine number_pairs
   end procedure per_node

   !> The per-node arrays of the step in one block (store), each starting in its own slot of
   !> WAY/SLOTS bytes of the L1 cache's way, away from the model's k and c that the sweeps
   !> read beside them (chain_links). A sweep streams up to ten such arrays at once; arrays
   !> allocated one by one start at the same offset of a page wherever a large one is mapped
   !> (glibc: 16 B past a page boundary), so their streams meet on the same cache sets and an
   !> 8-way cache holds only 8 of them (docs/performance.md "Where the time goes"). Placed
   !> from the block's true address, the layout does not depend on malloc.
   !> st > 0: the block could not be allocated.
   subroutine layout(self, m, st)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer, parameter :: U = 1, V = 2, A = 3, UN = 4, VN = 5, AN = 6, FE = 7, RP = 8, KG = 9, &
                            CG = 10
      integer :: len(CG), first(CG), off(CG), narr, j, slot, pos
      integer(c_intptr_t) :: base
      logical :: taken(0:SLOTS - 1)
      len = self%n + 1; len(RP:CG) = self%n
      first = 0; first(RP:CG) = 1           ! the index of each one's first entry
      narr = merge(RP, CG, self%chain_links)
      allocate (self%store(sum(len(1:narr)) + (narr + 1)*(WAY/8)), stat=st)
      if (st /= 0) return
      self%store = 0.0_dp
      ! the slots of the model's arrays the sweeps read beside these
      taken = .false.
      if (self%chain_links) then
         taken(slot_of(address(m%chain(1)%k(1)))) = .true.
         taken(slot_of(address(m%chain(1)%c(1)))) = .true.
      end if
      base = address(self%store(1))
      pos = 1; slot = 0
      do j = 1, narr
         do while (taken(modulo(slot, SLOTS)) .and. slot < 2*SLOTS)
            slot = slot + 1
         end do
         ! the first position from pos whose address is at the slot's start (mod WAY)
         pos = pos + int(modulo(modulo(slot, SLOTS)*(WAY/SLOTS) - (base + (pos - 1)*8_c_intptr_t), &
                                int(WAY, c_intptr_t))/8)
         off(j) = pos - first(j)
         taken(modulo(slot, SLOTS)) = .true.
         pos = pos + len(j)
      end do
      self%ou = off(U); self%ov = off(V); self%oa = off(A); self%oun = off(UN); self%ovn = off(VN)
      self%oan = off(AN); self%ofe = off(FE); self%orp = off(RP)
      if (.not. self%chain_links) then
         self%okg = off(KG); self%ocg = off(CG)
      end if
   contains
      integer function slot_of(addr)
         integer(c_intptr_t), intent(in) :: addr
         slot_of = int(modulo(addr, int(WAY, c_intptr_t))/(WAY/SLOTS))
      end function slot_of
   end subroutine layout

   !> The address of x (the layout's reckoning)
   integer(c_intptr_t) function address(x)
      real(dp), target, intent(in) :: x
      address = transfer(c_loc(x), 0_c_intptr_t)
   end function address

   !> The pair contacts' parameters: sign, gap, stiffness, damping and law, each one value for
   !> the chain (stride 0) where every pair has a contact and they share it, else one per
   !> pair: a first pass finds which, a second fills the arrays per pair (no array of all
   !> pairs is made for a parameter they share).
   subroutine pair_parameters(self, m, st)
      class(chain_step_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer :: n, i
      real(dp) :: s1, g1, k1, c1, si, gi, ki, ci
      integer(int8) :: l1, li
      logical :: has, one(5)
      n = m%n
      ! a pair without a contact: a gap no motion closes
      one = n > 1
      call law_of(1, has, s1, g1, k1, c1, l1)
      self%blk%kelvin = l1 /= AFFINE_LINEAR
      do i = 1, n - 1
         call law_of(i, has, si, gi, ki, ci, li)
         if (.not. has) one = .false.
         one = one .and. [si == s1, gi == g1, ki == k1, ci == c1, li == l1]
         self%blk%kelvin = self%blk%kelvin .or. li /= AFFINE_LINEAR
      end do
      st = 0
      call arrange(self%blk%sgn, self%blk%ss, one(1), s1, 1.0_dp)
      call arrange(self%blk%gap, self%blk%sg, one(2), g1, huge(1.0_dp))
      call arrange(self%blk%k, self%blk%sk, one(3), k1, 0.0_dp)
      call arrange(self%blk%c, self%blk%sc, one(4), c1, 0.0_dp)
      if (st /= 0) return
      allocate (self%blk%law(0:merge(0, n, one(5))), stat=st)
      if (st /= 0) return
      self%blk%sl = merge(0, 1, one(5)); self%blk%law = merge(l1, AFFINE_LINEAR, one(5))
      do i = 1, n - 1
         call law_of(i, has, si, gi, ki, ci, li)
         if (.not. one(1)) self%blk%sgn(i) = si
         if (.not. one(2)) self%blk%gap(i) = gi
         if (.not. one(3)) self%blk%k(i) = ki
         if (.not. one(4)) self%blk%c(i) = ci
         if (.not. one(5)) self%blk%law(i) = li
      end do
   contains
      !> pair i's contact (has: it has one) and law; a gap no motion closes where it has none
      subroutine law_of(i, has, sgn, gap, k, c, law)
         integer, intent(in) :: i
         logical, intent(out) :: has
         real(dp), intent(out) :: sgn, gap, k, c
         integer(int8), intent(out) :: law
         integer :: j, a, b, scheme, claw
         real(dp) :: par(NPAR_CONTACT), mstar
         sgn = 1.0_dp; gap = huge(1.0_dp); k = 0.0_dp; c = 0.0_dp; law = AFFINE_LINEAR
         j = self%pair_contact(i)
         has = j > 0
         if (.not. has) return
         call model_contact_at(m, j, a, b, gap, scheme, claw, par)
         sgn = merge(1.0_dp, -1.0_dp, a == i)
         k = par(P_STIFF)
         if (claw /= LAW_KELVIN) return
         ! the damping of a target restitution, with the pair's m* (as effective_mass_prepare
         ! gives the contacts added one by one)
         c = par(P_DAMPING)
         if (par(P_RESTITUTION) >= 0.0_dp) then
            mstar = pair_effective_mass(m, a, b)
            c = 0.0_dp
            if (ieee_is_finite(mstar)) c = damping_from_restitution(claw, par(P_RESTITUTION), par, &
                                                                    mstar)
         end if
         law = merge(AFFINE_KELVIN_CLIPPED, AFFINE_KELVIN, par(P_CLIP) > 0.5_dp)
      end subroutine law_of

      !> x as one value (x(0) = x1, stride 0), or one per pair (0:n, stride 1), none where
      !> there is no contact (the ends 0 and n, and until the second pass fills the pairs)
      subroutine arrange(x, stride, shared, x1, none)
         real(dp), allocatable, intent(out) :: x(:)
         integer, intent(out) :: stride
         logical, intent(in) :: shared
         real(dp), intent(in) :: x1, none
         if (st /= 0) return
         allocate (x(0:merge(0, n, shared)), stat=st)
         if (st /= 0) return
         stride = merge(0, 1, shared)
         x = merge(x1, none, shared)
      end subroutine arrange
   end subroutine pair_parameters
end submodule per_node_layout
