!> The chains of a model (docs/c-api.md "Chains"): a chain added whole and held per node
!> (model_add_chain), the numbering of its links and contacts among all the model's items
!> (spring then dashpot of each node, contacts between neighbours, in the order of the
!> calls), and the chains made into items one by one for the methods that take them so —
!> on a copy (model_expanded), never on the caller's model. A submodule of martello_model,
!> kept with the rest of the chain path (fortran/chain/).
submodule (martello_model) chains
   implicit none

contains

   !> Add a chain (chain_t) on nodes first … first + n − 1: k(n) the springs to ground; c(n)
   !> the dashpots (0: none; absent: none), fy(n), rho(n) the bilinear springs' yield force
   !> and hardening (absent: linear springs); gap(n − 1) the contacts between neighbours
   !> (absent: none) with scheme, law and par. Every link and contact is checked as add_link
   !> and add_contact check it; the first bad one stops the call, and the message names it
   !> (`chain entry i`, 0-based node of the chain). Items added one by one and chains are
   !> numbered in the order of the calls.
   module procedure model_add_chain
      type(chain_t), allocatable :: grown(:)
      type(chain_t) :: new
      real(dp) :: lp(NPAR_LINK)
      integer :: i, kind
      character(len=24) :: num
      stat = MARTELLO_OK
      if (n < 1 .or. first < 1 .or. first + n - 1 > m%n) then
         call refuse(m, stat, 'add_chain: its nodes first ... first + n - 1 must be nodes of the model'//&
                   ' (n >= 1)'); return
      end if
      if (present(fy) .neqv. present(rho)) then
         call refuse(m, stat, 'add_chain: give both fy and hardening (bilinear springs) or neither')
         return
      end if
      kind = merge(LINK_BILINEAR, LINK_SPRING, present(fy))
      do i = 1, n
         lp = 0.0_dp; lp(L_STIFF) = k(i)
         if (present(fy)) then
            lp(L_YIELD) = fy(i); lp(L_HARDENING) = rho(i)
         end if
         call model_check_link(m, kind, first + i - 1, 0, lp, stat)
         if (stat == MARTELLO_OK .and. present(c)) then
            if (.not. (c(i) >= 0.0_dp .and. ieee_is_finite(c(i)))) &
               call refuse(m, stat, 'add_chain: dashpot c must be finite and >= 0 (0: none)')
         end if
         if (stat == MARTELLO_OK .and. present(gap) .and. i < n) &
            call model_check_contact(m, first + i - 1, first + i, gap(i), scheme, law, par, stat)
         if (stat /= MARTELLO_OK) then
            write (num, '(i0)') i - 1
            m%errmsg = 'chain entry '//trim(num)//': '//trim(m%errmsg); return
         end if
      end do
      ! the new chain's arrays and the grown list allocated before anything moves: a failure
      ! leaves the model as it was
      allocate (new%k(n), stat=stat)
      if (stat == 0 .and. present(c)) allocate (new%c(n), stat=stat)
      if (stat == 0 .and. present(fy)) allocate (new%fy(n), new%rho(n), stat=stat)
      ! the gaps: one value where they are all the same (8 B per node less)
      if (stat == 0 .and. present(gap) .and. n > 1) &
         allocate (new%gap(merge(1, n - 1, all(gap(1:n - 1) == gap(1)))), stat=stat)
      if (stat == 0) allocate (grown(m%nchain + 1), stat=stat)
      if (stat /= 0) then
         write (num, '(i0)') n
         call out_of_memory('a chain of '//trim(num)//' nodes', REAL_BYTES*n*(1 + merge(1, 0, present(c)) &
                            + merge(2, 0, present(fy)) + merge(1, 0, present(gap))), &
                            FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      new%first = first; new%n = n
      new%glink = m%nlink; new%gcontact = m%ncontact
      new%link0 = model_nlinks(m); new%contact0 = model_ncontacts(m)
      new%k = k(1:n)
      new%nlink = n
      if (present(c)) then
         new%c = c(1:n); new%nlink = n + count(c(1:n) > 0.0_dp)
      end if
      if (present(fy)) then
         new%fy = fy(1:n); new%rho = rho(1:n)
      end if
      if (present(gap) .and. n > 1) then
         new%gap = gap(1:size(new%gap)); new%ncontact = n - 1
      end if
      new%scheme = scheme; new%law = law; new%par = par
      do i = 1, m%nchain
         call move_chain(m%chain(i), grown(i))
      end do
      call move_chain(new, grown(m%nchain + 1))
      call move_alloc(grown, m%chain)
      m%nchain = m%nchain + 1
   contains
      !> to ← from, the arrays moved, not copied
      subroutine move_chain(from, to)
         type(chain_t), intent(inout) :: from
         type(chain_t), intent(inout) :: to
         to%first = from%first; to%n = from%n; to%nlink = from%nlink; to%ncontact = from%ncontact
         to%link0 = from%link0; to%contact0 = from%contact0
         to%glink = from%glink; to%gcontact = from%gcontact
         to%scheme = from%scheme; to%law = from%law; to%par = from%par
         call move_alloc(from%k, to%k); call move_alloc(from%c, to%c)
         call move_alloc(from%fy, to%fy); call move_alloc(from%rho, to%rho)
         call move_alloc(from%gap, to%gap)
      end subroutine move_chain
   end procedure model_add_chain

   !> A chain refused: msg says why (martello_model's fail, which gfortran does not export to
   !> a submodule: a private procedure of the parent's object)
   subroutine refuse(m, stat, msg)
      type(model_t), intent(inout) :: m
      integer, intent(out) :: stat
      character(len=*), intent(in) :: msg
      stat = MARTELLO_ERR_ARGUMENT
      m%errmsg = msg
   end subroutine refuse

   !> Links of the model: added one by one and in chains.
   module procedure model_nlinks
      nl = m%nlink
      if (m%nchain > 0) nl = nl + sum(m%chain(1:m%nchain)%nlink)
   end procedure model_nlinks

   !> Contacts of the model: added one by one and in chains.
   module procedure model_ncontacts
      nc = m%ncontact
      if (m%nchain > 0) nc = nc + sum(m%chain(1:m%nchain)%ncontact)
   end procedure model_ncontacts

   !> The number of link j added one by one among all the model's links (the chains added
   !> before it count theirs).
   module procedure model_link_index
      idx = j
      if (m%nchain > 0) idx = idx + sum(m%chain(1:m%nchain)%nlink, m%chain(1:m%nchain)%glink < j)
   end procedure model_link_index

   !> The number of contact j added one by one among all the model's contacts.
   module procedure model_contact_index
      idx = j
      if (m%nchain > 0) &
         idx = idx + sum(m%chain(1:m%nchain)%ncontact, m%chain(1:m%nchain)%gcontact < j)
   end procedure model_contact_index

   !> Link number j of all the model's links (one by one or in a chain): kind, nodes and
   !> parameters.
   module procedure model_link_at
      integer :: q, i, pos, g
      g = j
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            if (j > ch%link0 .and. j <= ch%link0 + ch%nlink) then
               ! the spring, then (where c > 0) the dashpot of each node, in order
               pos = ch%link0
               do i = 1, ch%n
                  par = 0.0_dp; a = ch%first + i - 1; b = 0
                  pos = pos + 1
                  if (pos == j) then
                     kind = LINK_SPRING; par(L_STIFF) = ch%k(i)
                     if (allocated(ch%fy)) then
                        kind = LINK_BILINEAR; par(L_YIELD) = ch%fy(i); par(L_HARDENING) = ch%rho(i)
                     end if
                     return
                  end if
                  if (allocated(ch%c)) then
                     if (ch%c(i) > 0.0_dp) pos = pos + 1
                     if (pos == j) then
                        kind = LINK_DASHPOT; par(L_DAMP) = ch%c(i); return
                     end if
                  end if
               end do
            end if
            ! one added one by one after this chain: its number among those
            if (ch%link0 < j) g = g - ch%nlink
         end associate
      end do
      kind = m%link_kind(g); par = m%link_par(:, g)
      call row_pair(m%lnk, g, a, b)             ! one added one by one: a node pair's row
   end procedure model_link_at

   !> Contact number j of all the model's contacts (one by one or in a chain): nodes, gap,
   !> scheme, law and parameters.
   module procedure model_contact_at
      integer :: q, g
      g = j
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            if (j > ch%contact0 .and. j <= ch%contact0 + ch%ncontact) then
               a = ch%first + (j - ch%contact0) - 1; b = a + 1
               gap = ch%gap(min(j - ch%contact0, size(ch%gap)))
               scheme = ch%scheme; law = ch%law; par = ch%par
               return
            end if
            ! one added one by one after this chain: its number among those
            if (ch%contact0 < j) g = g - ch%ncontact
         end associate
      end do
      call row_pair(m%con, g, a, b)             ! one added one by one: a node pair's row
      gap = m%con_gap(g); scheme = m%con_scheme(g)
      law = m%con_law(g); par = m%con_par(:, g)
   end procedure model_contact_at

   !> The chains as links and contacts one by one, numbered as model_add_chain says, for the
   !> methods that take items one by one (a run's integrator, the static solve); the free
   !> capacity of model_create is kept.
   !> stat, message: as martello_status out_of_memory if they cannot be allocated (the model
   !> is left as it was).
   module procedure model_expand_chains
      integer :: nl, nc, free_l, free_c, q, i, g, pos
      integer, allocatable :: lk(:), cs(:), cl(:)
      real(dp), allocatable :: lpar(:, :), cg(:), cpar(:, :), cm(:)
      type(rows_t) :: lr, cr
      character(len=96) :: what
      stat = MARTELLO_OK
      if (m%nchain == 0) return
      nl = model_nlinks(m); nc = model_ncontacts(m)
      free_l = size(m%link_kind) - m%nlink; free_c = size(m%con_scheme) - m%ncontact
      allocate (lk(nl + free_l), lpar(NPAR_LINK, nl + free_l), &
                cs(nc + free_c), cl(nc + free_c), &
                cg(nc + free_c), cm(nc + free_c), cpar(NPAR_CONTACT, nc + free_c), stat=stat)
      if (stat == 0) call rows_init(lr, nl + free_l, 2, stat)
      if (stat == 0) call rows_init(cr, nc + free_c, 2, stat)
      if (stat /= 0) then
         write (what, '(a,i0,a,i0,a)') 'the chains as ', nl + free_l, ' links and ', nc + free_c, &
            ' contacts one by one'
         call out_of_memory(trim(what), REAL_BYTES*(NPAR_LINK*real(nl + free_l, dp) &
                            + (NPAR_CONTACT + 2.0_dp)*(nc + free_c)) &
                            + (REAL_BYTES + INT_BYTES)*2.0_dp*(nl + free_l + nc + free_c) &
                            + INT_BYTES*(real(nl + free_l, dp) + 2.0_dp*(nc + free_c)), &
                            FIX_SMALLER_SCENE, stat, message)
         return
      end if
      cm = 0.0_dp
      ! in the order of the calls: the items added one by one before each chain, the chain
      pos = 0; g = 0
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            call copy_links(ch%glink)
            do i = 1, ch%n
               pos = pos + 1
               call rows_append_pair(lr, ch%first + i - 1, 0, stat)
               lpar(:, pos) = 0.0_dp
               lk(pos) = LINK_SPRING; lpar(L_STIFF, pos) = ch%k(i)
               if (allocated(ch%fy)) then
                  lk(pos) = LINK_BILINEAR; lpar(L_YIELD, pos) = ch%fy(i)
                  lpar(L_HARDENING, pos) = ch%rho(i)
               end if
               if (.not. allocated(ch%c)) cycle
               if (.not. (ch%c(i) > 0.0_dp)) cycle
               pos = pos + 1
               call rows_append_pair(lr, ch%first + i - 1, 0, stat)
               lpar(:, pos) = 0.0_dp
               lk(pos) = LINK_DASHPOT; lpar(L_DAMP, pos) = ch%c(i)
            end do
         end associate
      end do
      call copy_links(m%nlink)
      pos = 0; g = 0
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            call copy_contacts(ch%gcontact)
            do i = 1, ch%ncontact
               pos = pos + 1
               call rows_append_pair(cr, ch%first + i - 1, ch%first + i, stat)
               cg(pos) = ch%gap(min(i, size(ch%gap)))
               cs(pos) = ch%scheme; cl(pos) = ch%law; cpar(:, pos) = ch%par
            end do
         end associate
      end do
      call copy_contacts(m%ncontact)
      if (stat /= 0) then
         call out_of_memory('the rows of the chains one by one', &
                            (REAL_BYTES + INT_BYTES)*2.0_dp*(nl + nc), FIX_SMALLER_SCENE, stat, message)
         return
      end if
      call move_alloc(lk, m%link_kind); call move_alloc(lpar, m%link_par)
      call move_alloc(cs, m%con_scheme)
      call move_alloc(cl, m%con_law); call move_alloc(cg, m%con_gap)
      call move_alloc(cpar, m%con_par); call move_alloc(cm, m%con_mstar)
      call rows_move(lr, m%lnk); call rows_move(cr, m%con)
      m%nlink = nl; m%ncontact = nc
      deallocate (m%chain); m%nchain = 0
   contains
      !> The links added one by one after link g up to link last, into the rows after pos
      !> (g, pos: the last copied and written); stops at a failure (stat)
      subroutine copy_links(last)
         integer, intent(in) :: last
         integer :: st
         do while (g < last .and. stat == 0)
            g = g + 1; pos = pos + 1
            lk(pos) = m%link_kind(g); lpar(:, pos) = m%link_par(:, g)
            call rows_append(lr, m%lnk%node(row_lo(m%lnk, g):row_hi(m%lnk, g)), &
                             m%lnk%coef(row_lo(m%lnk, g):row_hi(m%lnk, g)), st)
            if (st /= 0) stat = st
         end do
      end subroutine copy_links
      !> The contacts added one by one after contact g up to contact last, as copy_links
      subroutine copy_contacts(last)
         integer, intent(in) :: last
         integer :: st
         do while (g < last .and. stat == 0)
            g = g + 1; pos = pos + 1
            cg(pos) = m%con_gap(g)
            cs(pos) = m%con_scheme(g); cl(pos) = m%con_law(g); cpar(:, pos) = m%con_par(:, g)
            call rows_append(cr, m%con%node(row_lo(m%con, g):row_hi(m%con, g)), &
                             m%con%coef(row_lo(m%con, g):row_hi(m%con, g)), st)
            if (st /= 0) stat = st
         end do
      end subroutine copy_contacts
   end procedure model_expand_chains

   !> A copy of the model that the caller owns with its chains made into links and contacts
   !> one by one (model_expand_chains): what a method that takes items one by one runs on,
   !> so that running a model never changes it. stat, message: as out_of_memory if the
   !> copy cannot be made (copy is then not allocated).
   module procedure model_expanded
      allocate (copy, source=m, stat=stat)
      if (stat /= 0) then
         call out_of_memory('a copy of the model with its chains as links and contacts', &
                            -1.0_dp, FIX_SMALLER_SCENE, stat, message)
         return
      end if
      call model_expand_chains(copy, stat, message)
      if (stat /= MARTELLO_OK) deallocate (copy)
   end procedure model_expanded
end submodule chains
