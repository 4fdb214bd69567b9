/* SPDX-License-Identifier: MIT */
/*
 * The heap policy, applied once per process (docs/decisions.md, 'Process settings:
 * malloc keeps its heap'): glibc's malloc serves every request from its heap (M_MMAP_MAX = 0)
 * and never returns freed memory at the top of the heap to the system
 * (M_TRIM_THRESHOLD = -1, "disables trimming completely", mallopt(3)). Without it each
 * block above glibc's largest dynamic mmap threshold (32 MiB), such as the working
 * memory of every UMFPACK numeric factorisation, is a fresh mapping that the kernel
 * zero-fills page by page, and a freed block at the top of the heap goes back to the
 * system to be faulted in again at the next request. When the heap cannot grow, glibc
 * still maps memory (and other threads' arenas always do), so no request fails for it.
 * Left alone when the user tunes malloc (GLIBC_TUNABLES naming glibc.malloc., or one of
 * the MALLOC_*_ variables) and with a C library other than glibc.
 */
#define _GNU_SOURCE
#include <stdlib.h>
#include <string.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

static int applied = -1;

/* The user's environment decides malloc's parameters. */
static int malloc_left_to_user(void)
{
    const char *tunables = getenv("GLIBC_TUNABLES");
    if (tunables && strstr(tunables, "glibc.malloc.")) return 1;
    return getenv("MALLOC_MMAP_MAX_") || getenv("MALLOC_TRIM_THRESHOLD_")
        || getenv("MALLOC_MMAP_THRESHOLD_") || getenv("MALLOC_TOP_PAD_");
}

/* 1 if this process runs with the policy (set by this or an earlier call), else 0. */
int yarnfort_apply_heap_policy(void)
{
    if (applied >= 0) return applied;
    applied = 0;
#ifdef __GLIBC__
    if (!malloc_left_to_user()) {
        applied = mallopt(M_MMAP_MAX, 0) == 1 && mallopt(M_TRIM_THRESHOLD, -1) == 1;
    }
#endif
    return applied;
}
