/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * Restores whole-buffer parsing for VTK's XML readers under a current Debian 12 expat.
 *
 * expat 2.5.0-1+deb12u2 and later backport reparse deferral (CVE-2023-52425): a token that does
 * not end in the buffer given to XML_Parse is kept for later. ParaView 5.11's VTK 9.2 hands the
 * parser a file's XML header in pieces and then reads the appended data block itself at the offset
 * the parser reports (VTK issue 19258), so with deferral the offset is wrong and readers return
 * empty data: pvpython opens a .vti with 0 points and MPI redistribution loses what ranks send.
 * Debian's VTK 9.1 carries VTK's fix; its ParaView does not.
 *
 * This library defines XML_ParserCreate, creates the parser with the real expat (the next
 * definition in the lookup order) and turns deferral off where the function exists (expat
 * >= 2.6, or Debian's backport). It must come before libexpat in the symbol lookup order: ICTK's
 * executables link it first (ICTK::ExpatFix); Python, pvpython, pvbatch and paraview get it
 * through LD_PRELOAD (Scripts/paraview, the ctest environment). With an expat that has no
 * deferral it changes nothing.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <expat.h>
#include <pthread.h>
#include <stddef.h>

typedef XML_Parser (*ictk_create_fn)(const XML_Char*);
typedef XML_Bool (*ictk_defer_fn)(XML_Parser, XML_Bool);

static ictk_create_fn ictk_real_create = NULL;
static ictk_defer_fn ictk_set_deferral = NULL;
static pthread_once_t ictk_once = PTHREAD_ONCE_INIT;

static void ictk_resolve(void)
{
  ictk_real_create = (ictk_create_fn)dlsym(RTLD_NEXT, "XML_ParserCreate");
  ictk_set_deferral = (ictk_defer_fn)dlsym(RTLD_NEXT, "XML_SetReparseDeferralEnabled");
}

/* Exported under expat's own name: this is the interposition. */
__attribute__((visibility("default"))) XML_Parser XML_ParserCreate(const XML_Char* encoding)
{
  pthread_once(&ictk_once, ictk_resolve);
  if (!ictk_real_create)
  {
    return NULL; /* no expat in the process: the caller reports a parser it could not create */
  }
  XML_Parser parser = ictk_real_create(encoding);
  if (parser && ictk_set_deferral)
  {
    ictk_set_deferral(parser, XML_FALSE);
  }
  return parser;
}

/* For a check that the interposer is the one in use (Testing/VTK/TestExpatFix). */
__attribute__((visibility("default"))) int ictk_expat_fix_active(void)
{
  pthread_once(&ictk_once, ictk_resolve);
  return ictk_set_deferral != NULL;
}
