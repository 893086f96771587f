! A real Fortran program on the draglab_mod bindings (what an MFiX-style solver does).
!
! Set-up: a fresh database at the path given as the first argument (deleted first), seeded with
! the literature library; the law is bvk2007@1 (Beetstra, van der Hoef & Kuipers 2007).
! Reference values: F(0.1, 0) = 2.42878 and F(0.4, 100) = 30.7416, the BVK 2007 formula evaluated
! independently from the published coefficients (reference dossier drag_laws.md section 2.4 and its
! law_check_values.csv, 6 significant figures): tolerance 1e-5 relative covers that rounding.
! beta is checked against the canonical identity beta = 18 mu phi eps F / d^2 of the brief
! (tolerance 1e-13 relative: a few rounding errors in a different order of operations).
! Exits with status 1 if any check fails.
program fortran_api_test
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_long_long, c_associated
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use draglab_mod
  implicit none

  character(len=4096) :: path
  type(draglab_db_t) :: db
  type(draglab_law_t) :: law, missing
  real(c_double) :: F, beta, dga, K, nan, untouched, phi, re, gamma, re_p
  real(c_double) :: eps_g, mu_g, rho_g, slip, d_p, rho_s
  real(c_double) :: phis(4), res(4), Fs(4)
  integer(c_long_long) :: count
  integer :: failures, i

  failures = 0
  untouched = -12345.0_c_double
  nan = ieee_value(0.0_c_double, ieee_quiet_nan)

  call get_command_argument(1, path)
  if (len_trim(path) == 0) then
    print '(A)', 'usage: fortran_api_test DATABASE_PATH'
    error stop 2
  end if
  call delete_file(trim(path))

  call expect_status(draglab_db_open(trim(path), db), DRAGLAB_OK, 'open a fresh database')
  call expect_status(draglab_law_load(db, 'bvk2007@1', law), DRAGLAB_OK, 'load bvk2007@1')
  if (failures > 0) error stop 1

  ! Identity of the loaded law.
  call expect_true(draglab_law_name(law) == 'bvk2007', 'name is bvk2007')
  call expect_true(draglab_law_version(law) == 1, 'version is 1')
  call expect_true(draglab_law_form(law) == 'bvk2007', 'form is bvk2007')
  call expect_true(len(draglab_law_hash(law)) == 64, 'hash has 64 hex digits')
  call expect_true(draglab_law_num_extra(law) == 0, 'no extra inputs')
  call expect_true(len(draglab_version()) > 0, 'library version')

  ! Published check values.
  F = untouched
  call expect_status(draglab_law_F(law, 0.1_c_double, 0.0_c_double, F), DRAGLAB_OK, 'F(0.1, 0)')
  call expect_close(F, 2.42878_c_double, 1.0e-5_c_double, 'F(0.1, 0) = 2.42878')
  call expect_status(draglab_law_F(law, 0.4_c_double, 100.0_c_double, F), DRAGLAB_OK, &
                     'F(0.4, 100)')
  call expect_close(F, 30.7416_c_double, 1.0e-5_c_double, 'F(0.4, 100) = 30.7416')

  ! K and beta from the same F (canonical identities).
  call expect_status(draglab_law_K(law, 0.4_c_double, 100.0_c_double, K), DRAGLAB_OK, 'K')
  call expect_close(K, F / 0.6_c_double, 1.0e-13_c_double, 'K = F / (1 - phi)')
  eps_g = 0.6_c_double
  mu_g = 1.8e-5_c_double
  rho_g = 1.2_c_double
  d_p = 5.0e-4_c_double
  rho_s = 2500.0_c_double
  slip = 0.2_c_double
  phi = 1.0_c_double - eps_g
  re = rho_g * eps_g * d_p * slip / mu_g
  call expect_status(draglab_law_F(law, phi, re, F), DRAGLAB_OK, 'F for beta')
  call expect_status(draglab_law_beta(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, beta), &
                     DRAGLAB_OK, 'beta')
  call expect_close(beta, 18.0_c_double * mu_g * phi * eps_g * F / d_p**2, 1.0e-13_c_double, &
                    'beta = 18 mu phi eps F / d^2')
  call expect_status(draglab_law_dga(law, eps_g, mu_g, rho_g, slip, d_p, rho_s, dga), &
                     DRAGLAB_OK, 'dga')
  call expect_close(dga, beta / phi, 1.0e-13_c_double, 'lDgA = beta / phi')
  ! CFD-DEM per particle: gamma = beta V_p / phi for equal spheres, at the particle Re.
  call expect_status(draglab_law_particle_drag(law, eps_g, mu_g, rho_g, slip, d_p, d_p, gamma, &
                     re_p), DRAGLAB_OK, 'particle drag')
  call expect_close(gamma, beta * (acos(-1.0_c_double) * d_p**3 / 6.0_c_double) / phi, &
                    1.0e-13_c_double, 'gamma = beta V_p / phi')
  call expect_close(re_p, re, 1.0e-13_c_double, 'particle Re = rho eps d slip / mu')

  ! Errors come back as statuses, the output untouched, never as NaN.
  F = untouched
  call expect_status(draglab_law_F(law, 1.2_c_double, 10.0_c_double, F), &
                     DRAGLAB_INVALID_ARGUMENT, 'phi = 1.2 is invalid')
  call expect_true(index(draglab_last_error(), 'phi') > 0, 'message names phi')
  call expect_status(draglab_law_F(law, nan, 10.0_c_double, F), DRAGLAB_INVALID_ARGUMENT, &
                     'phi = NaN is invalid')
  call expect_status(draglab_law_F(law, 0.3_c_double, nan, F), DRAGLAB_INVALID_ARGUMENT, &
                     'Re = NaN is invalid')
  call expect_status(draglab_law_F(law, 0.3_c_double, -1.0_c_double, F), &
                     DRAGLAB_INVALID_ARGUMENT, 'Re = -1 is invalid')
  call expect_true(F == untouched, 'F untouched by failing calls')
  beta = untouched
  call expect_status(draglab_law_beta(law, 1.2_c_double, mu_g, rho_g, slip, d_p, rho_s, beta), &
                     DRAGLAB_INVALID_ARGUMENT, 'eps_g = 1.2 is invalid')
  call expect_status(draglab_law_beta(law, eps_g, mu_g, rho_g, slip, d_p, 0.0_c_double, beta), &
                     DRAGLAB_INVALID_ARGUMENT, 'rho_s = 0 is invalid')
  call expect_true(beta == untouched, 'beta untouched by failing calls')

  ! Range policies: phi = 0.05 is below the validity box (phi >= 0.1).
  call expect_status(draglab_law_F(law, 0.05_c_double, 10.0_c_double, F), &
                     DRAGLAB_OUT_OF_VALIDITY, 'phi = 0.05 is outside the validity box')
  call expect_status(draglab_law_set_range_policy(law, DRAGLAB_RANGE_CLAMP), DRAGLAB_OK, 'clamp')
  call expect_status(draglab_law_F(law, 0.05_c_double, 10.0_c_double, F), DRAGLAB_OK, &
                     'clamped evaluation')
  call expect_status(draglab_law_F(law, 0.1_c_double, 10.0_c_double, K), DRAGLAB_OK, &
                     'F at the box edge')
  call expect_true(F == K, 'clamped to the box edge')
  call expect_status(draglab_law_out_of_range_count(law, count), DRAGLAB_OK, 'count')
  call expect_true(count == 1_c_long_long, 'one clamped evaluation counted')
  call expect_status(draglab_law_set_range_policy(law, 9), DRAGLAB_INVALID_ARGUMENT, &
                     'unknown policy')
  call expect_status(draglab_law_set_range_policy(law, DRAGLAB_RANGE_ERROR), DRAGLAB_OK, 'error')

  ! Array path equals the scalar path.
  phis = [0.1_c_double, 0.25_c_double, 0.4_c_double, 0.6_c_double]
  res = [0.0_c_double, 3.0_c_double, 100.0_c_double, 1000.0_c_double]
  call expect_status(draglab_law_F_n(law, phis, res, Fs), DRAGLAB_OK, 'array path')
  do i = 1, 4
    call expect_status(draglab_law_F(law, phis(i), res(i), F), DRAGLAB_OK, 'scalar path')
    call expect_true(Fs(i) == F, 'array value equals scalar value')
  end do
  res(3) = nan
  call expect_status(draglab_law_F_n(law, phis, res, Fs), DRAGLAB_INVALID_ARGUMENT, &
                     'NaN in the array')
  call expect_true(index(draglab_last_error(), 'index 2') > 0, 'message names index 2 (0-based)')

  ! Unknown law; the law outlives its database.
  call expect_status(draglab_law_load(db, 'no_such_law', missing), DRAGLAB_NOT_FOUND, &
                     'unknown law')
  call draglab_db_close(db)
  call expect_status(draglab_law_F(law, 0.4_c_double, 100.0_c_double, F), DRAGLAB_OK, &
                     'evaluation after closing the database')
  call expect_close(F, 30.7416_c_double, 1.0e-5_c_double, 'same value after closing')
  call draglab_law_free(law)

  ! The same file read-only, as a solver reading a shared installation it cannot write.
  call expect_status(draglab_db_open_readonly(trim(path), db), DRAGLAB_OK, 'open read-only')
  call expect_status(draglab_law_load(db, 'bvk2007@1', law), DRAGLAB_OK, 'load read-only')
  call expect_status(draglab_law_F(law, 0.4_c_double, 100.0_c_double, F), DRAGLAB_OK, &
                     'F read-only')
  call expect_close(F, 30.7416_c_double, 1.0e-5_c_double, 'F(0.4, 100) = 30.7416 read-only')
  call draglab_law_free(law)
  call draglab_db_close(db)
  call delete_file(trim(path))
  call expect_status(draglab_db_open_readonly(trim(path), db), DRAGLAB_NOT_FOUND, &
                     'a read-only open does not create a missing file')
  call expect_true(.not. c_associated(db%handle), 'no handle for a missing file')

  if (failures > 0) then
    print '(I0, A)', failures, ' check(s) failed'
    error stop 1
  end if
  print '(A)', 'fortran_api_test: all checks passed'

contains

  subroutine expect_status(status, expected, what)
    integer(c_int), intent(in) :: status, expected
    character(len=*), intent(in) :: what
    if (status /= expected) then
      failures = failures + 1
      print '(A, A, I0, A, I0, A, A)', 'FAIL: ', what, ': status ', status, ' (expected ', &
            expected, ') ', draglab_last_error()
    end if
  end subroutine expect_status

  subroutine expect_close(actual, expected, tolerance, what)
    real(c_double), intent(in) :: actual, expected, tolerance
    character(len=*), intent(in) :: what
    if (.not. (abs(actual - expected) <= tolerance * abs(expected))) then
      failures = failures + 1
      print '(A, A, A, ES24.16, A, ES24.16)', 'FAIL: ', what, ': got ', actual, ', expected ', &
            expected
    end if
  end subroutine expect_close

  subroutine expect_true(condition, what)
    logical, intent(in) :: condition
    character(len=*), intent(in) :: what
    if (.not. condition) then
      failures = failures + 1
      print '(A, A)', 'FAIL: ', what
    end if
  end subroutine expect_true

  subroutine delete_file(name)
    character(len=*), intent(in) :: name
    character(len=4) :: suffixes(3) = ['    ', '-wal', '-shm']
    integer :: unit, ios, k
    do k = 1, 3
      open(newunit=unit, file=name // trim(suffixes(k)), status='old', iostat=ios)
      if (ios == 0) close(unit, status='delete')
    end do
  end subroutine delete_file

end program fortran_api_test
