/*
 * Start-up for a Cortex-M4F without a C library: the vector table, the reset handler
 * (FPU on, .data copied, .bss zeroed, main, exit) and the fault handlers; semihosting.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "semihosting.h"

/* From link.ld. */
extern uint32_t __stack_top[];
extern uint32_t __data_start[], __data_end[], __data_load[];
extern uint32_t __bss_start[], __bss_end[];

int main(void);

enum {
    SYS_OPEN = 0x01,
    SYS_WRITE = 0x05,
    SYS_EXIT = 0x18,
    OPEN_MODE_W = 4, /* fopen's "w" */
    ADP_STOPPED_APPLICATION_EXIT = 0x20026,
    ADP_STOPPED_RUN_TIME_ERROR_UNKNOWN = 0x20023,
};

static int semihosting_call(int operation, const void *argument) {
    register int r0 __asm__("r0") = operation;
    register const void *r1 __asm__("r1") = argument;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

/* The host's stdout: the special file ":tt" opened for writing (SYS_WRITE0 would go to
 * QEMU's stderr). */
static int stdout_handle = -1;

void semihosting_write(const char *text) {
    if (stdout_handle < 0) {
        static const char tt[] = ":tt";
        const uintptr_t open[3] = { (uintptr_t)tt, OPEN_MODE_W, sizeof tt - 1 };
        stdout_handle = semihosting_call(SYS_OPEN, open);
    }
    size_t len = 0;
    while (text[len] != '\0') {
        len++;
    }
    const uintptr_t write[3] = { (uintptr_t)stdout_handle, (uintptr_t)text, len };
    semihosting_call(SYS_WRITE, write);
}

_Noreturn void semihosting_exit(bool success) {
    /* On 32-bit Arm, SYS_EXIT takes the reason itself in r1. */
    semihosting_call(SYS_EXIT, (const void *)(uintptr_t)(success ? ADP_STOPPED_APPLICATION_EXIT
                                                                 : ADP_STOPPED_RUN_TIME_ERROR_UNKNOWN));
    for (;;) {
        __asm__ volatile("wfi");
    }
}

_Noreturn void Reset_Handler(void) {
    /* Full access to the FPU (CP10, CP11) before any floating-point instruction. */
    volatile uint32_t *const cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");

    for (uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = __bss_start; dst < __bss_end;) {
        *dst++ = 0;
    }
    semihosting_exit(main() == 0);
}

/* Any fault ends the run as a failure. gyro-ffi never panics; if it did, its panic handler
 * would execute `udf`, which lands here. */
_Noreturn static void Fault_Handler(void) {
    semihosting_write("fault: the firmware took an exception (HardFault or other)\n");
    semihosting_exit(false);
}

typedef void (*Vector)(void);

/* The Cortex-M vector table: initial stack pointer, then the handlers. QEMU's mps2-an386
 * reads it at address 0 on reset. */
__attribute__((section(".vectors"), used)) static const Vector vectors[16] = {
    (Vector)(uintptr_t)__stack_top, /* initial SP */
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0, 0, 0, 0,
    Fault_Handler, /* SVCall */
    Fault_Handler, /* DebugMonitor */
    0,
    Fault_Handler, /* PendSV */
    Fault_Handler, /* SysTick */
};
