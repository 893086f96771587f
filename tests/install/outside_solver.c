/* An "outside solver": links libdraglab through pkg-config or find_package, opens a database,
 * loads bvk2007 and checks F(0.4, 100) = 30.7416 (data/law_check_values.csv, 6 significant
 * figures: tolerance 2e-6 relative). Usage: outside_solver DATABASE_PATH */
#include <draglab/draglab.h>
#include <math.h>
#include <stdio.h>

int main(int argc, char** argv) {
  draglab_db* db = NULL;
  draglab_law* law = NULL;
  double F = 0.0;
  if (argc != 2) return 2;
  if (draglab_db_open(argv[1], &db) != DRAGLAB_OK || draglab_law_load(db, "bvk2007", &law) != 0 ||
      draglab_law_F(law, 0.4, 100.0, &F) != DRAGLAB_OK) {
    fprintf(stderr, "error: %s\n", draglab_last_error());
    return 1;
  }
  draglab_law_free(law);
  draglab_db_close(db);
  if (fabs(F - 30.7416) / 30.7416 > 2e-6) {
    fprintf(stderr, "F = %.9g, expected 30.7416\n", F);
    return 1;
  }
  printf("outside solver: bvk2007 F(0.4, 100) = %.6f\n", F);
  return 0;
}
