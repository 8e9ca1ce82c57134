/*
 * stdlib.h - stand-in for the riscv64-unknown-elf freestanding compile of
 * libcdsp (see math.h here): lib/edges.c includes <stdlib.h> for abs() only.
 */
#ifndef CDSP_FREESTANDING_STDLIB_H
#define CDSP_FREESTANDING_STDLIB_H

#define abs(x) __builtin_abs(x)

#endif
