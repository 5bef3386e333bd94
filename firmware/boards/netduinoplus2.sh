#!/bin/sh
# Runner for STM32F407 images (`FAINT_BOARD=stm32f407`) on QEMU's netduinoplus2 (an
# STM32F405: the F407's flash and SRAM map; QEMU 7.2 maps 192 KiB of SRAM at 0x2000_0000
# and no CCM, so an image with statics in `.ccm` links but does not run here). As the
# default runner: `-icount shift=10` makes TIM2 (prescaler 1023) count executed
# instructions; semihosting carries the output and the exit status. Use it with
#   CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUNNER=boards/netduinoplus2.sh cargo run ...
exec qemu-system-arm -machine netduinoplus2 -nographic \
    -semihosting-config enable=on,target=native \
    -icount shift=10,align=off,sleep=off -kernel "$@"
