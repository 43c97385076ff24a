#!/bin/sh
# Runs a firmware ELF (fog-app) under QEMU with its four UARTs on loopback TCP: the
# runner behind `cargo fw-run` (.cargo/config.toml), see docs/guide/firmware.md "Running fog-app".
#
#   scripts/fw-qemu.sh ELF [FIRMWARE-ARGUMENT...]
#
# UART0, host port (upload, monitor):   QEMU listens on 127.0.0.1:$FOG_HOST_PORT (4444)
# UART1, gyro frames   (fogsim rig):    QEMU connects to 127.0.0.1:$FOG_GYRO_PORT (4445)
# UART2, turntable     (fogsim rig):    QEMU connects to 127.0.0.1:$FOG_TABLE_PORT (4446)
# UART3, inclinometer  (fogsim rig):    QEMU connects to 127.0.0.1:$FOG_INCL_PORT (4447)
#   (unused when the firmware argument tilt-mdeg= selects the simulated inclinometer)
# The rig's ports are retried every second until the rig listens. Firmware arguments
# (docs/guide/firmware.md, "Firmware arguments") go to the firmware through semihosting; they
# cannot contain a comma.
set -eu
if [ $# -lt 1 ]; then
    echo "usage: $0 ELF [FIRMWARE-ARGUMENT...]" >&2
    exit 2
fi
elf=$1
shift
semi="enable=on,target=native,arg=$(basename "$elf")"
for a in "$@"; do
    case $a in
    *,*)
        echo "$0: firmware argument '$a' contains a comma (QEMU cannot pass it)" >&2
        exit 2
        ;;
    esac
    semi="$semi,arg=$a"
done
host=${FOG_HOST_PORT:-4444}
gyro=${FOG_GYRO_PORT:-4445}
table=${FOG_TABLE_PORT:-4446}
incl=${FOG_INCL_PORT:-4447}
exec qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
    -semihosting-config "$semi" \
    -serial "tcp:127.0.0.1:$host,server=on,wait=off" \
    -serial "tcp:127.0.0.1:$gyro,reconnect=1" \
    -serial "tcp:127.0.0.1:$table,reconnect=1" \
    -serial "tcp:127.0.0.1:$incl,reconnect=1" \
    -kernel "$elf"
