/*
 * string.h - stand-in for the riscv64-unknown-elf freestanding compile of
 * libcdsp (see math.h here). A freestanding gcc still emits calls to
 * memcpy/memset/memmove/memcmp (struct copies, clears), which every
 * freestanding environment must provide; the library's own uses map to the
 * builtins. size_t comes from the compiler's <stddef.h>.
 */
#ifndef CDSP_FREESTANDING_STRING_H
#define CDSP_FREESTANDING_STRING_H

#include <stddef.h>

#define memset(d, c, n) __builtin_memset(d, c, n)
#define memcpy(d, s, n) __builtin_memcpy(d, s, n)
#define memmove(d, s, n) __builtin_memmove(d, s, n)
#define memcmp(a, b, n) __builtin_memcmp(a, b, n)

#endif
