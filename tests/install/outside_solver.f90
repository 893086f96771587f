! An "outside" Fortran solver built with `pkg-config --cflags --libs draglab-fortran`: opens a
! database, loads bvk2007 and checks F(0.4, 100) = 30.7416 (data/law_check_values.csv, 6
! significant figures: tolerance 2e-6 relative). Usage: outside_solver_f DATABASE_PATH
program outside_solver_f
  use, intrinsic :: iso_c_binding, only: c_double
  use draglab_mod
  implicit none
  type(draglab_db_t) :: db
  type(draglab_law_t) :: law
  real(c_double) :: F
  character(len=512) :: path

  call get_command_argument(1, path)
  if (draglab_db_open(trim(path), db) /= DRAGLAB_OK) then
    print *, 'error: ', draglab_last_error()
    stop 1
  end if
  if (draglab_law_load(db, 'bvk2007', law) /= DRAGLAB_OK) then
    print *, 'error: ', draglab_last_error()
    stop 1
  end if
  if (draglab_law_F(law, 0.4_c_double, 100.0_c_double, F) /= DRAGLAB_OK) stop 1
  call draglab_law_free(law)
  call draglab_db_close(db)
  if (abs(F - 30.7416_c_double) / 30.7416_c_double > 2.0e-6_c_double) then
    print *, 'F = ', F, ' expected 30.7416'
    stop 1
  end if
  print '(a, f10.6)', 'outside Fortran solver: bvk2007 F(0.4, 100) = ', F
end program outside_solver_f
