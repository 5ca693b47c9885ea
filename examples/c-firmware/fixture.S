/* The recorded rate words (fixtures/firmware/bench_run_20s.i16be, found through the
 * assembler's include path): big-endian i16 counts at 1 kHz in the ±300 °/s range. */
    .section .rodata.rate_words, "a"
    .balign 2
    .global rate_words
rate_words:
    .incbin "bench_run_20s.i16be"
    .global rate_words_end
rate_words_end:
