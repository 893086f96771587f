/* The C ABI from a C99 program (compiled as C, with -pedantic): what a C solver does.
 *
 * Set-up: a fresh database at the path given as the first argument (removed first); the law is
 * bvk2007@1 (Beetstra, van der Hoef & Kuipers 2007). Reference values: F(0.1, 0) = 2.42878 and
 * F(0.4, 100) = 30.7416, the BVK 2007 formula evaluated independently from the published
 * coefficients (reference dossier drag_laws.md section 2.4, 6 significant figures): tolerance
 * 1e-5 relative covers that rounding. Exit status 1 if any check fails. */
#include <draglab/draglab.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static int failures = 0;

static void expect(int condition, const char* what) {
  if (!condition) {
    ++failures;
    fprintf(stderr, "FAIL: %s (last error: %s)\n", what, draglab_last_error());
  }
}

int main(int argc, char** argv) {
  draglab_db* db = NULL;
  draglab_law* law = NULL;
  double F = -1.0, values[3];
  const double phi[3] = {0.1, 0.4, 0.6};
  const double re[3] = {0.0, 100.0, 1000.0};
  char wal[4096], shm[4096];
  if (argc != 2) {
    fprintf(stderr, "usage: c_api_c_test DATABASE_PATH\n");
    return 2;
  }
  remove(argv[1]);
  snprintf(wal, sizeof wal, "%s-wal", argv[1]);
  snprintf(shm, sizeof shm, "%s-shm", argv[1]);
  remove(wal);
  remove(shm);
  expect(draglab_db_open(argv[1], &db) == DRAGLAB_OK, "open a fresh database");
  if (db == NULL) return 1;
  expect(draglab_law_load(db, "bvk2007", &law) == DRAGLAB_OK, "load bvk2007 (latest)");
  if (law == NULL) return 1;
  expect(strcmp(draglab_law_name(law), "bvk2007") == 0, "name");
  expect(draglab_law_F(law, 0.1, 0.0, &F) == DRAGLAB_OK, "F(0.1, 0)");
  expect(fabs(F - 2.42878) <= 1e-5 * 2.42878, "F(0.1, 0) = 2.42878");
  expect(draglab_law_F(law, 0.4, 100.0, &F) == DRAGLAB_OK, "F(0.4, 100)");
  expect(fabs(F - 30.7416) <= 1e-5 * 30.7416, "F(0.4, 100) = 30.7416");
  F = -1.0;
  expect(draglab_law_F(law, 1.2, 10.0, &F) == DRAGLAB_INVALID_ARGUMENT, "phi = 1.2 refused");
  expect(strstr(draglab_last_error(), "phi") != NULL, "message names phi");
  expect(draglab_law_F(law, 0.3, NAN, &F) == DRAGLAB_INVALID_ARGUMENT, "Re = NaN refused");
  expect(F == -1.0, "output untouched on error");
  expect(draglab_law_F_n(law, 3, phi, re, values) == DRAGLAB_OK, "array path");
  expect(draglab_law_F(law, 0.6, 1000.0, &F) == DRAGLAB_OK && values[2] == F,
         "array value equals scalar value");
  draglab_law_free(law);
  draglab_db_close(db);
  /* The same file read-only, as a solver reading a shared installation. */
  db = NULL;
  law = NULL;
  expect(draglab_db_open_readonly(argv[1], &db) == DRAGLAB_OK, "open read-only");
  expect(db != NULL && draglab_law_load(db, "bvk2007@1", &law) == DRAGLAB_OK,
         "load bvk2007@1 read-only");
  expect(law != NULL && draglab_law_F(law, 0.4, 100.0, &F) == DRAGLAB_OK &&
             fabs(F - 30.7416) <= 1e-5 * 30.7416,
         "F(0.4, 100) = 30.7416 read-only");
  draglab_law_free(law);
  draglab_db_close(db);
  remove(argv[1]);
  remove(wal);
  remove(shm);
  db = NULL;
  expect(draglab_db_open_readonly(argv[1], &db) == DRAGLAB_NOT_FOUND && db == NULL,
         "a missing file is not created by a read-only open");
  remove(argv[1]);
  if (failures > 0) return 1;
  printf("c_api_c_test: all checks passed\n");
  return 0;
}
