# bristle: top-level entry points, a thin wrapper over the CMake presets
# (CMakePresets.json). `make help` lists the targets; V=1 shows the commands.
SHELL := bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:
.SUFFIXES:
MAKEFLAGS += --no-print-directory

V ?= 0
ifeq ($(V),1)
  Q :=
  NINJA_QUIET :=
else
  Q := @
  NINJA_QUIET := -- --quiet
endif

JOBS       ?= 2
PYTHON     := .venv/bin/python
IMAGE      := build/cm7-release/hal/stm32h7/br_image_stm32h7.elf
FLASH_KIB  := 2048
RAM_KIB    := 128
DEMO_OUT   := out/demo
TUNE_OUT   := out/tune
BENCH_OUT  := out/bench
BENCH      := build/host-release/sim/bench/br_bench

# $(call configure,<preset>): cmake --preset, output shown only on failure.
# Always run: cheap when nothing changed, and it picks up edited presets.
define configure
	$(Q)echo "== configure $(1)"
	$(Q)log="$$(cmake --preset $(1) 2>&1)" || { echo "$$log"; echo "configure $(1) failed" >&2; exit 1; }
endef

# $(call build,<preset>)
define build
	$(Q)echo "== build $(1)"
	$(Q)cmake --build --preset $(1) $(NINJA_QUIET)
endef

# Flash = text + data (the .data image is stored in flash), RAM = data + bss
# (bss includes the reserved stack), from arm-none-eabi-size (Berkeley format).
define print_size
	$(Q)test -f $(IMAGE) || { echo "no firmware image at $(IMAGE)" >&2; exit 1; }
	$(Q)arm-none-eabi-size $(IMAGE) | awk -v fk=$(FLASH_KIB) -v rk=$(RAM_KIB) -v img=$(IMAGE) ' \
	  NR == 2 { f = $$1 + $$2; r = $$2 + $$3; ok = 1; \
	    printf "firmware %s\n", img; \
	    printf "  flash: %7d bytes (text %d + data %d)  %5.2f%% of %d KiB\n", f, $$1, $$2, 100 * f / (fk * 1024), fk; \
	    printf "  RAM:   %7d bytes (data %d + bss %d)   %5.2f%% of %d KiB DTCM\n", r, $$2, $$3, 100 * r / (rk * 1024), rk } \
	  END { exit ok ? 0 : 1 }'
endef

.PHONY: help deps build test demo bench firmware regen clean distclean

help:
	@echo "bristle targets:"
	@echo "  make deps      install Debian packages and the pinned .venv (cmake/setup-deps.sh)"
	@echo "  make build     configure + build host-debug (ASan + UBSan)"
	@echo "  make test      host-debug build + ctest, then the firmware image and its size"
	@echo "  make demo      host-release build, run the circle demo into $(DEMO_OUT), plot it"
	@echo "  make bench     host-release build, time the PF (C and numpy) and the UKF, memory -> $(BENCH_OUT)/bench.json"
	@echo "  make firmware  cross build (cm7-release) and print flash / RAM use"
	@echo "  make regen     regenerate the generated headers and the golden traces"
	@echo "  make tune      Nelder-Mead tuning of the PF and UKF noise (regenerates sim/circle/gen/)"
	@echo "  make clean     remove build/ and out/ (distclean also removes .venv)"
	@echo "  V=1 shows the commands; JOBS=n sets the ctest parallelism (default 2)"

deps:
	$(Q)cmake/setup-deps.sh

build: deps
	$(call configure,host-debug)
	$(call build,host-debug)

# The release tools (the estimator tuner) are built first: the regen test of the
# tuned configurations runs them unsanitised, at full speed.
test: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(call configure,host-debug)
	$(call build,host-debug)
	$(Q)echo "== test host-debug"
	$(Q)ctest --preset host-debug --output-on-failure -j$(JOBS)
	$(call configure,cm7-release)
	$(call build,cm7-release)
	$(print_size)

demo: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== demo -> $(DEMO_OUT)"
	$(Q)mkdir -p $(DEMO_OUT)
	$(Q)build/host-release/sim/br_demo_circle --out $(DEMO_OUT)
	$(Q)MPLBACKEND=Agg $(PYTHON) sim/plots/plot_demo.py $(DEMO_OUT)

# Nelder-Mead tuning of the PF's and the UKF's noise variances on the circle
# (thesis section 3.2): regenerates sim/circle/gen/br_{pf,ukf}_tuned.h, with the
# progress logs and thesis Fig. 1 in $(TUNE_OUT). docs/tuning.md.
tune: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)mkdir -p $(TUNE_OUT)
	$(Q)build/host-release/sim/br_tune_est --est ukf --out sim/circle/gen/br_ukf_tuned.h --log $(TUNE_OUT)/ukf.csv
	$(Q)build/host-release/sim/br_tune_est --est pf --out sim/circle/gen/br_pf_tuned.h --log $(TUNE_OUT)/pf.csv
	$(Q)MPLBACKEND=Agg $(PYTHON) sim/plots/plot_tuning.py $(TUNE_OUT)/fig1_tuning.png $(TUNE_OUT)/pf.csv:"H-inf + PF" $(TUNE_OUT)/ukf.csv:"H-inf + UKF"

# C bench (records the input, times PF and UKF, memory), then the numpy PF on
# the same recording; the script prints the summary table and merges both into
# bench.json. docs/bench.md.
bench: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== bench -> $(BENCH_OUT)"
	$(Q)mkdir -p $(BENCH_OUT)
	$(Q)$(BENCH) --json $(BENCH_OUT)/c.json --record $(BENCH_OUT)/pf_input.csv
	$(Q)$(PYTHON) sim/bench/pf_numpy.py $(BENCH_OUT)/pf_input.csv --c-json $(BENCH_OUT)/c.json --out $(BENCH_OUT)/bench.json

firmware: deps
	$(call configure,cm7-release)
	$(call build,cm7-release)
	$(print_size)

regen: deps
	$(Q)echo "== regen: machine parameters, gains"
	$(Q)$(PYTHON) firmware/design/gen_machine.py
	$(Q)$(PYTHON) firmware/design/synth_hinf.py
	$(Q)$(PYTHON) firmware/design/gen_noise.py
	$(Q)echo "== regen: golden traces"
	$(Q)$(PYTHON) golden/gen_traces.py

clean:
	$(Q)rm -rf build out

distclean: clean
	$(Q)rm -rf .venv
