/* no_flock.c: an LD_PRELOAD shim for tests that makes every flock() fail with ENOLCK, as on a
 * filesystem without locks (some network filesystems), which the machines running the tests do
 * not have. */
#include <errno.h>

int flock(int fd, int operation) {
  (void)fd;
  (void)operation;
  errno = ENOLCK;
  return -1;
}
