/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * A file that changes while a program reads it, made exact for Reliability.VanishingFiles
 * (docs/reliability.md): loaded with LD_PRELOAD, this wraps read(2) and, when a read of the file
 * ICTK_FAULT_PATH (its absolute path) would pass byte ICTK_FAULT_AFTER, strikes once, as another
 * program or a failing disk would at that moment:
 *
 *   ICTK_FAULT=truncate  the file is cut to ICTK_FAULT_AFTER bytes (a copy or a save in progress
 *                        replacing it: the reader meets its end early);
 *   ICTK_FAULT=vanish    the file is unlinked and every later read of it fails with EIO, as on a
 *                        network or removable disk that went away (on a local disk an unlinked
 *                        file stays readable through the descriptors already open).
 *
 * Reads through the C++ streams and ::read come here; the fault is timed in bytes of the file, so
 * a test does not race the program it tests.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef ssize_t (*ictk_read_fn)(int, void*, size_t);

static int ictk_struck_fd = -1; /* the descriptor of the vanished file (its reads fail) */
static int ictk_struck = 0;

static int ictk_is_target(int fd, const char* target)
{
  char link[64];
  char path[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0)
  {
    return 0;
  }
  path[n] = '\0';
  return strcmp(path, target) == 0;
}

ssize_t read(int fd, void* buffer, size_t count)
{
  static ictk_read_fn real = NULL;
  if (!real)
  {
    real = (ictk_read_fn)dlsym(RTLD_NEXT, "read");
  }
  const char* target = getenv("ICTK_FAULT_PATH");
  if (ictk_struck && fd == ictk_struck_fd)
  {
    errno = EIO;
    return -1;
  }
  if (!target || ictk_struck || !ictk_is_target(fd, target))
  {
    return real(fd, buffer, count);
  }
  const char* after_text = getenv("ICTK_FAULT_AFTER");
  const char* fault = getenv("ICTK_FAULT");
  const off_t after = after_text ? (off_t)strtoll(after_text, NULL, 10) : 0;
  const off_t at = lseek(fd, 0, SEEK_CUR);
  if (at < 0 || at + (off_t)count <= after)
  {
    return real(fd, buffer, count);
  }
  ictk_struck = 1;
  if (fault && strcmp(fault, "vanish") == 0)
  {
    unlink(target);
    ictk_struck_fd = fd;
    errno = EIO;
    return -1;
  }
  if (truncate(target, after) != 0)
  {
    return -1;
  }
  return real(fd, buffer, count);
}
