# SPDX-License-Identifier: Apache-2.0
# Warning sets. Firmware: float32 only, every implicit conversion is an error.
set(BR_FIRMWARE_WARNINGS
    -Wall -Wextra -Wpedantic -Werror
    -Wdouble-promotion -Wconversion -Wsign-conversion -Wshadow
    -Wstrict-prototypes -Wmissing-prototypes -Wundef -Wvla
    -Wcast-qual)
# Host simulator and tests: double precision allowed, still warning-free.
set(BR_HOST_WARNINGS -Wall -Wextra -Wpedantic -Werror -Wshadow -Wvla)
