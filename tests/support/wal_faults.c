/* wal_faults.c: an LD_PRELOAD shim for the database fault tests. It acts on writes to a file
 * whose name ends in "-wal" (SQLite's write-ahead log, where every change of a draglab database
 * is written first), after the number of such writes given in DRAGLAB_TEST_WAL_WRITES:
 *   DRAGLAB_TEST_WAL_FAULT=full   every later one fails with ENOSPC (a full disk);
 *   DRAGLAB_TEST_WAL_FAULT=stall  the next one first creates the file named in
 *                                 DRAGLAB_TEST_WAL_STALLED, then waits to be killed (a process
 *                                 killed half-way through a commit).
 * Without DRAGLAB_TEST_WAL_FAULT it does nothing. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

static int is_wal(int fd) {
  char link[64], path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 4) return 0;
  path[n] = 0;
  return strcmp(path + n - 4, "-wal") == 0;
}

/* 1 when this write must fail (errno set). */
static int fault(int fd) {
  static long remaining = -2; /* -2: not read yet; -1: no fault */
  static int stall = 0;
  if (remaining == -2) {
    const char* kind = getenv("DRAGLAB_TEST_WAL_FAULT");
    const char* count = getenv("DRAGLAB_TEST_WAL_WRITES");
    remaining = kind == NULL ? -1 : (count ? atol(count) : 0);
    stall = kind != NULL && strcmp(kind, "stall") == 0;
  }
  if (remaining < 0 || !is_wal(fd)) return 0;
  if (remaining > 0) {
    --remaining;
    return 0;
  }
  if (stall) {
    const char* marker = getenv("DRAGLAB_TEST_WAL_STALLED");
    if (marker != NULL) close(open(marker, O_CREAT | O_WRONLY, 0644));
    for (;;) pause();
  }
  errno = ENOSPC;
  return 1;
}

#define FORWARD(name, ...)                                                \
  static ssize_t (*real)() = NULL;                                        \
  if (real == NULL) real = (ssize_t(*)())dlsym(RTLD_NEXT, name);          \
  if (fault(fd)) return -1;                                               \
  return real(__VA_ARGS__);

ssize_t write(int fd, const void* buf, size_t count) { FORWARD("write", fd, buf, count) }
ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  FORWARD("pwrite", fd, buf, count, offset)
}
ssize_t pwrite64(int fd, const void* buf, size_t count, off_t offset) {
  FORWARD("pwrite64", fd, buf, count, offset)
}
