/*
 * Arm semihosting: the program's console and exit status under QEMU (-semihosting-config
 * enable=on) or a debugger. On a wrench, replace these two by a UART and a reset.
 */
#ifndef SEMIHOSTING_H
#define SEMIHOSTING_H

#include <stdbool.h>

/* Writes the NUL-terminated `text` to the host's stdout (SYS_OPEN ":tt", SYS_WRITE). */
void semihosting_write(const char *text);

/* Ends the run: QEMU exits with status 0 if `success`, else 1 (SYS_EXIT). */
_Noreturn void semihosting_exit(bool success);

#endif /* SEMIHOSTING_H */
