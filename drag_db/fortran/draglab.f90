! draglab_mod: Fortran 2003 bindings (iso_c_binding) of the libdraglab C ABI (draglab/draglab.h).
!
!   use draglab_mod
!   type(draglab_db_t)  :: db
!   type(draglab_law_t) :: law
!   real(c_double)      :: F
!   if (draglab_db_open('draglab.db', db) /= DRAGLAB_OK) print *, draglab_last_error()
!   if (draglab_law_load(db, 'bvk2007@1', law) /= DRAGLAB_OK) stop 1
!   if (draglab_law_F(law, 0.3_c_double, 50.0_c_double, F) /= DRAGLAB_OK) stop 1
!   call draglab_law_free(law)
!   call draglab_db_close(db)
!
! The procedures have the names and argument order of the C functions and return the same integer
! status (DRAGLAB_OK = 0). Scalars are real(c_double) (= double precision); strings are ordinary
! Fortran character variables (trailing blanks are trimmed). On error the outputs are untouched and
! draglab_last_error() says why (per thread).
!
! Conventions: phi solids fraction, eps = 1 - phi; Re = rho eps d u / mu with u the interstitial
! slip; F = F_d / (3 pi mu d eps u), drag only; beta = 18 mu phi eps F / d^2 [kg m^-3 s^-1].
module draglab_mod
  use, intrinsic :: iso_c_binding
  implicit none
  private

  ! Status codes (draglab.h).
  integer(c_int), parameter, public :: DRAGLAB_OK = 0
  integer(c_int), parameter, public :: DRAGLAB_INVALID_ARGUMENT = 1
  integer(c_int), parameter, public :: DRAGLAB_OUT_OF_VALIDITY = 2
  integer(c_int), parameter, public :: DRAGLAB_NOT_FOUND = 3
  integer(c_int), parameter, public :: DRAGLAB_IMMUTABLE = 4
  integer(c_int), parameter, public :: DRAGLAB_DATABASE_ERROR = 5
  integer(c_int), parameter, public :: DRAGLAB_SCHEMA_TOO_NEW = 6
  integer(c_int), parameter, public :: DRAGLAB_NOT_A_DATABASE = 7
  integer(c_int), parameter, public :: DRAGLAB_INTERNAL = 8
  integer(c_int), parameter, public :: DRAGLAB_IO_ERROR = 9
  ! Range policies for inputs outside the law's validity box.
  integer(c_int), parameter, public :: DRAGLAB_RANGE_ERROR = 0
  integer(c_int), parameter, public :: DRAGLAB_RANGE_CLAMP = 1
  integer(c_int), parameter, public :: DRAGLAB_RANGE_EXTRAPOLATE = 2

  ! Opaque handles.
  type, public :: draglab_db_t
    type(c_ptr) :: handle = c_null_ptr
  end type draglab_db_t
  type, public :: draglab_law_t
    type(c_ptr) :: handle = c_null_ptr
  end type draglab_law_t

  public :: draglab_version, draglab_last_error
  public :: draglab_db_open, draglab_db_open_readonly, draglab_db_close
  public :: draglab_law_load, draglab_law_free
  public :: draglab_law_name, draglab_law_version, draglab_law_form, draglab_law_hash
  public :: draglab_law_num_extra, draglab_law_validity
  public :: draglab_law_set_range_policy, draglab_law_range_policy, draglab_law_out_of_range_count
  public :: draglab_law_F, draglab_law_F_extra, draglab_law_F_n
  public :: draglab_law_beta_d2_over_mu, draglab_law_K
  public :: draglab_law_beta, draglab_law_dga, draglab_law_beta_n
  public :: draglab_law_particle_drag

  ! The C functions, under c_-prefixed Fortran names.
  interface
    function c_draglab_version() bind(C, name='draglab_version') result(s)
      import :: c_ptr
      type(c_ptr) :: s
    end function
    function c_draglab_last_error() bind(C, name='draglab_last_error') result(s)
      import :: c_ptr
      type(c_ptr) :: s
    end function
    function c_draglab_db_open(path, db) bind(C, name='draglab_db_open') result(status)
      import :: c_char, c_ptr, c_int
      character(kind=c_char), intent(in) :: path(*)
      type(c_ptr), intent(inout) :: db
      integer(c_int) :: status
    end function
    function c_draglab_db_open_readonly(path, db) bind(C, name='draglab_db_open_readonly') &
        result(status)
      import :: c_char, c_ptr, c_int
      character(kind=c_char), intent(in) :: path(*)
      type(c_ptr), intent(inout) :: db
      integer(c_int) :: status
    end function
    subroutine c_draglab_db_close(db) bind(C, name='draglab_db_close')
      import :: c_ptr
      type(c_ptr), value :: db
    end subroutine
    function c_draglab_law_load(db, ref, law) bind(C, name='draglab_law_load') result(status)
      import :: c_char, c_ptr, c_int
      type(c_ptr), value :: db
      character(kind=c_char), intent(in) :: ref(*)
      type(c_ptr), intent(inout) :: law
      integer(c_int) :: status
    end function
    subroutine c_draglab_law_free(law) bind(C, name='draglab_law_free')
      import :: c_ptr
      type(c_ptr), value :: law
    end subroutine
    function c_draglab_law_name(law) bind(C, name='draglab_law_name') result(s)
      import :: c_ptr
      type(c_ptr), value :: law
      type(c_ptr) :: s
    end function
    function c_draglab_law_form(law) bind(C, name='draglab_law_form') result(s)
      import :: c_ptr
      type(c_ptr), value :: law
      type(c_ptr) :: s
    end function
    function c_draglab_law_hash(law) bind(C, name='draglab_law_hash') result(s)
      import :: c_ptr
      type(c_ptr), value :: law
      type(c_ptr) :: s
    end function
    function c_draglab_law_version(law) bind(C, name='draglab_law_version') result(v)
      import :: c_ptr, c_int
      type(c_ptr), value :: law
      integer(c_int) :: v
    end function
    function c_draglab_law_num_extra(law) bind(C, name='draglab_law_num_extra') result(n)
      import :: c_ptr, c_int
      type(c_ptr), value :: law
      integer(c_int) :: n
    end function
    function c_draglab_law_validity(law, phi_min, phi_max, re_min, re_max) &
        bind(C, name='draglab_law_validity') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), intent(inout) :: phi_min, phi_max, re_min, re_max
      integer(c_int) :: status
    end function
    function c_draglab_law_set_range_policy(law, policy) &
        bind(C, name='draglab_law_set_range_policy') result(status)
      import :: c_ptr, c_int
      type(c_ptr), value :: law
      integer(c_int), value :: policy
      integer(c_int) :: status
    end function
    function c_draglab_law_range_policy(law, policy) &
        bind(C, name='draglab_law_range_policy') result(status)
      import :: c_ptr, c_int
      type(c_ptr), value :: law
      integer(c_int), intent(inout) :: policy
      integer(c_int) :: status
    end function
    function c_draglab_law_out_of_range_count(law, count) &
        bind(C, name='draglab_law_out_of_range_count') result(status)
      import :: c_ptr, c_int, c_long_long
      type(c_ptr), value :: law
      integer(c_long_long), intent(inout) :: count
      integer(c_int) :: status
    end function
    function c_draglab_law_F(law, phi, re, F) bind(C, name='draglab_law_F') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: phi, re
      real(c_double), intent(inout) :: F
      integer(c_int) :: status
    end function
    function c_draglab_law_F_extra(law, phi, re, extra, F) &
        bind(C, name='draglab_law_F_extra') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: phi, re
      real(c_double), intent(in) :: extra(*)
      real(c_double), intent(inout) :: F
      integer(c_int) :: status
    end function
    function c_draglab_law_F_n(law, n, phi, re, F) bind(C, name='draglab_law_F_n') result(status)
      import :: c_ptr, c_int, c_double, c_size_t
      type(c_ptr), value :: law
      integer(c_size_t), value :: n
      real(c_double), intent(in) :: phi(*), re(*)
      real(c_double), intent(inout) :: F(*)
      integer(c_int) :: status
    end function
    function c_draglab_law_beta_d2_over_mu(law, phi, re, value) &
        bind(C, name='draglab_law_beta_d2_over_mu') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: phi, re
      real(c_double), intent(inout) :: value
      integer(c_int) :: status
    end function
    function c_draglab_law_K(law, phi, re, K) bind(C, name='draglab_law_K') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: phi, re
      real(c_double), intent(inout) :: K
      integer(c_int) :: status
    end function
    function c_draglab_law_beta(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, beta) &
        bind(C, name='draglab_law_beta') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: eps_g, mu_g, rho_g, slip, d_p, rho_s
      real(c_double), intent(inout) :: beta
      integer(c_int) :: status
    end function
    function c_draglab_law_particle_drag(law, eps_g, mu_g, rho_g, slip, d_i, d_mean, gamma, &
        re) bind(C, name='draglab_law_particle_drag') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: eps_g, mu_g, rho_g, slip, d_i, d_mean
      real(c_double), intent(inout) :: gamma, re
      integer(c_int) :: status
    end function
    function c_draglab_law_dga(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, dga) &
        bind(C, name='draglab_law_dga') result(status)
      import :: c_ptr, c_int, c_double
      type(c_ptr), value :: law
      real(c_double), value :: eps_g, mu_g, rho_g, slip, d_p, rho_s
      real(c_double), intent(inout) :: dga
      integer(c_int) :: status
    end function
    function c_draglab_law_beta_n(law, n, eps_g, mu_g, rho_g, slip, d_p, beta) &
        bind(C, name='draglab_law_beta_n') result(status)
      import :: c_ptr, c_int, c_double, c_size_t
      type(c_ptr), value :: law
      integer(c_size_t), value :: n
      real(c_double), intent(in) :: eps_g(*), mu_g(*), rho_g(*), slip(*), d_p(*)
      real(c_double), intent(inout) :: beta(*)
      integer(c_int) :: status
    end function
    function c_strlen(s) bind(C, name='strlen') result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function
  end interface

contains

  ! ---- string helpers --------------------------------------------------------------------------

  ! Fortran string -> NUL-terminated C string (trailing blanks trimmed).
  pure function to_c_string(s) result(c)
    character(len=*), intent(in) :: s
    character(kind=c_char, len=len_trim(s) + 1) :: c
    c = trim(s) // c_null_char
  end function to_c_string

  ! NUL-terminated C string owned by the library -> Fortran string (copied).
  function from_c_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function from_c_string

  ! ---- library ---------------------------------------------------------------------------------

  ! Library version, e.g. "0.1.0 (g1234abc)".
  function draglab_version() result(s)
    character(len=:), allocatable :: s
    s = from_c_string(c_draglab_version())
  end function draglab_version

  ! Message of the last failing call on this thread ("" if none).
  function draglab_last_error() result(s)
    character(len=:), allocatable :: s
    s = from_c_string(c_draglab_last_error())
  end function draglab_last_error

  ! ---- database --------------------------------------------------------------------------------

  ! Opens (creating and seeding if missing) a database; path '' -> $DRAGLAB_DB, else ./draglab.db.
  function draglab_db_open(path, db) result(status)
    character(len=*), intent(in) :: path
    type(draglab_db_t), intent(inout) :: db
    integer(c_int) :: status
    type(c_ptr) :: handle
    handle = c_null_ptr
    status = c_draglab_db_open(to_c_string(path), handle)
    if (status == DRAGLAB_OK) db%handle = handle
  end function draglab_db_open

  ! Opens an existing database read-only (a shared installation the solver cannot write): never
  ! writes, creates, migrates or seeds it. In a directory without write permission the file is
  ! read as immutable (changes made while it is open are not seen). A missing file gives
  ! DRAGLAB_NOT_FOUND; path '' -> $DRAGLAB_DB, else ./draglab.db.
  function draglab_db_open_readonly(path, db) result(status)
    character(len=*), intent(in) :: path
    type(draglab_db_t), intent(inout) :: db
    integer(c_int) :: status
    type(c_ptr) :: handle
    handle = c_null_ptr
    status = c_draglab_db_open_readonly(to_c_string(path), handle)
    if (status == DRAGLAB_OK) db%handle = handle
  end function draglab_db_open_readonly

  subroutine draglab_db_close(db)
    type(draglab_db_t), intent(inout) :: db
    if (c_associated(db%handle)) call c_draglab_db_close(db%handle)
    db%handle = c_null_ptr
  end subroutine draglab_db_close

  ! ---- laws ------------------------------------------------------------------------------------

  ! Loads 'name', 'name@3', 'name@latest' or 'name@<hash prefix>'. The law does not need the
  ! database afterwards.
  function draglab_law_load(db, ref, law) result(status)
    type(draglab_db_t), intent(in) :: db
    character(len=*), intent(in) :: ref
    type(draglab_law_t), intent(inout) :: law
    integer(c_int) :: status
    type(c_ptr) :: handle
    handle = c_null_ptr
    status = c_draglab_law_load(db%handle, to_c_string(ref), handle)
    if (status == DRAGLAB_OK) law%handle = handle
  end function draglab_law_load

  subroutine draglab_law_free(law)
    type(draglab_law_t), intent(inout) :: law
    if (c_associated(law%handle)) call c_draglab_law_free(law%handle)
    law%handle = c_null_ptr
  end subroutine draglab_law_free

  function draglab_law_name(law) result(s)
    type(draglab_law_t), intent(in) :: law
    character(len=:), allocatable :: s
    s = from_c_string(c_draglab_law_name(law%handle))
  end function draglab_law_name

  function draglab_law_form(law) result(s)
    type(draglab_law_t), intent(in) :: law
    character(len=:), allocatable :: s
    s = from_c_string(c_draglab_law_form(law%handle))
  end function draglab_law_form

  ! Content hash (64 hex digits).
  function draglab_law_hash(law) result(s)
    type(draglab_law_t), intent(in) :: law
    character(len=:), allocatable :: s
    s = from_c_string(c_draglab_law_hash(law%handle))
  end function draglab_law_hash

  ! Version number (-1 for an invalid handle).
  function draglab_law_version(law) result(v)
    type(draglab_law_t), intent(in) :: law
    integer(c_int) :: v
    v = c_draglab_law_version(law%handle)
  end function draglab_law_version

  ! Number of extra inputs (polydisperse forms: 1, the size ratio y = d_i/<d>; else 0).
  function draglab_law_num_extra(law) result(n)
    type(draglab_law_t), intent(in) :: law
    integer(c_int) :: n
    n = c_draglab_law_num_extra(law%handle)
  end function draglab_law_num_extra

  ! Validity box: phi in [phi_min, phi_max], Re in [re_min, re_max].
  function draglab_law_validity(law, phi_min, phi_max, re_min, re_max) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(inout) :: phi_min, phi_max, re_min, re_max
    integer(c_int) :: status
    status = c_draglab_law_validity(law%handle, phi_min, phi_max, re_min, re_max)
  end function draglab_law_validity

  ! DRAGLAB_RANGE_ERROR (default), DRAGLAB_RANGE_CLAMP or DRAGLAB_RANGE_EXTRAPOLATE.
  function draglab_law_set_range_policy(law, policy) result(status)
    type(draglab_law_t), intent(in) :: law
    integer, intent(in) :: policy
    integer(c_int) :: status
    status = c_draglab_law_set_range_policy(law%handle, int(policy, c_int))
  end function draglab_law_set_range_policy

  function draglab_law_range_policy(law, policy) result(status)
    type(draglab_law_t), intent(in) :: law
    integer, intent(inout) :: policy
    integer(c_int) :: status
    integer(c_int) :: p
    p = 0
    status = c_draglab_law_range_policy(law%handle, p)
    if (status == DRAGLAB_OK) policy = int(p)
  end function draglab_law_range_policy

  ! Number of clamped or extrapolated evaluations since load.
  function draglab_law_out_of_range_count(law, count) result(status)
    type(draglab_law_t), intent(in) :: law
    integer(c_long_long), intent(inout) :: count
    integer(c_int) :: status
    status = c_draglab_law_out_of_range_count(law%handle, count)
  end function draglab_law_out_of_range_count

  ! ---- evaluation ------------------------------------------------------------------------------

  ! Canonical drag-only F(phi, Re), dimensionless.
  function draglab_law_F(law, phi, re, F) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: phi, re
    real(c_double), intent(inout) :: F
    integer(c_int) :: status
    status = c_draglab_law_F(law%handle, phi, re, F)
  end function draglab_law_F

  ! F with the law's extra inputs (draglab_law_num_extra values).
  function draglab_law_F_extra(law, phi, re, extra, F) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: phi, re
    real(c_double), intent(in) :: extra(:)
    real(c_double), intent(inout) :: F
    integer(c_int) :: status
    if (size(extra) < draglab_law_num_extra(law)) then
      status = DRAGLAB_INVALID_ARGUMENT
      return
    end if
    if (size(extra) == 0) then
      status = c_draglab_law_F(law%handle, phi, re, F)
    else
      status = c_draglab_law_F_extra(law%handle, phi, re, extra, F)
    end if
  end function draglab_law_F_extra

  ! Array path: F(i) = F(phi(i), re(i)). The three arrays must have the same size (else
  ! DRAGLAB_INVALID_ARGUMENT). On error the contents of F are unspecified.
  function draglab_law_F_n(law, phi, re, F) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in), contiguous :: phi(:), re(:)
    real(c_double), intent(inout), contiguous :: F(:)
    integer(c_int) :: status
    if (size(re) /= size(phi) .or. size(F) /= size(phi)) then
      status = DRAGLAB_INVALID_ARGUMENT
      return
    end if
    status = c_draglab_law_F_n(law%handle, int(size(phi), c_size_t), phi, re, F)
  end function draglab_law_F_n

  ! beta d^2/mu = 18 phi (1 - phi) F.
  function draglab_law_beta_d2_over_mu(law, phi, re, value) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: phi, re
    real(c_double), intent(inout) :: value
    integer(c_int) :: status
    status = c_draglab_law_beta_d2_over_mu(law%handle, phi, re, value)
  end function draglab_law_beta_d2_over_mu

  ! K = F / (1 - phi), the total force including the mean pressure gradient part.
  function draglab_law_K(law, phi, re, K) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: phi, re
    real(c_double), intent(inout) :: K
    integer(c_int) :: status
    status = c_draglab_law_K(law%handle, phi, re, K)
  end function draglab_law_K

  ! Friction coefficient beta [kg m^-3 s^-1], argument order of MFiX's DRAG_USR: gas fraction,
  ! gas viscosity [Pa s], gas density [kg/m^3], interstitial slip [m/s], particle diameter [m],
  ! particle density [kg/m^3] (must be > 0; unused).
  function draglab_law_beta(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, beta) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: eps_g, mu_g, rho_g, slip, d_p, rho_s
    real(c_double), intent(inout) :: beta
    integer(c_int) :: status
    status = c_draglab_law_beta(law%handle, eps_g, mu_g, rho_g, slip, d_p, rho_s, beta)
  end function draglab_law_beta

  ! MFiX's DRAG_USR output lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1] (MFiX
  ! multiplies it by EP_SM, by EP_SM/EPg for model B, or by the particle volume in DES).
  function draglab_law_dga(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, dga) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: eps_g, mu_g, rho_g, slip, d_p, rho_s
    real(c_double), intent(inout) :: dga
    integer(c_int) :: status
    status = c_draglab_law_dga(law%handle, eps_g, mu_g, rho_g, slip, d_p, rho_s, dga)
  end function draglab_law_dga

  ! CFD-DEM per-particle drag: gamma [kg/s] with drag on the particle = gamma (u_f - u_p), and the
  ! particle Reynolds number re; d_mean is the Sauter mean diameter around the particle, used by
  ! polydisperse laws (y = d_i/d_mean) and ignored by the others. See draglab.h.
  function draglab_law_particle_drag(law, eps_g, mu_g, rho_g, slip, d_i, d_mean, gamma, re) &
      result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in) :: eps_g, mu_g, rho_g, slip, d_i, d_mean
    real(c_double), intent(inout) :: gamma, re
    integer(c_int) :: status
    status = c_draglab_law_particle_drag(law%handle, eps_g, mu_g, rho_g, slip, d_i, d_mean, &
                                         gamma, re)
  end function draglab_law_particle_drag

  ! Array path of beta over cells or particles (all arrays of the same size).
  function draglab_law_beta_n(law, eps_g, mu_g, rho_g, slip, d_p, beta) result(status)
    type(draglab_law_t), intent(in) :: law
    real(c_double), intent(in), contiguous :: eps_g(:), mu_g(:), rho_g(:), slip(:), d_p(:)
    real(c_double), intent(inout), contiguous :: beta(:)
    integer(c_int) :: status
    integer :: n
    n = size(eps_g)
    if (size(mu_g) /= n .or. size(rho_g) /= n .or. size(slip) /= n .or. size(d_p) /= n .or. &
        size(beta) /= n) then
      status = DRAGLAB_INVALID_ARGUMENT
      return
    end if
    status = c_draglab_law_beta_n(law%handle, int(n, c_size_t), eps_g, mu_g, rho_g, slip, d_p, &
                                  beta)
  end function draglab_law_beta_n

end module draglab_mod
