# SPDX-License-Identifier: Apache-2.0
# bristle: top-level entry points, a thin wrapper over the CMake presets
# (CMakePresets.json). `make help` lists the targets; V=1 shows the commands.
SHELL := bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:
.SUFFIXES:
MAKEFLAGS += --no-print-directory

# User values (paths, names, numbers) never become shell or make text
# (docs/tools.md, "Inputs that cannot inject"): each is taken as it was
# given ($(value ...): a "$(...)" in it is not a make function), then
# reaches the recipes only as an environment variable, BR_MK_<NAME>, which a
# recipe quotes ("$$BR_MK_MACHINE"); BOARD and the counts must match what
# they select. tests/machine/test_hostile_inputs.py holds the Makefile to it.
V ?= 0
ifeq ($(value V),1)
  Q :=
  NINJA_QUIET :=
else
  Q := @
  NINJA_QUIET := -- --quiet
endif

JOBS       ?= 2
PYTHON     := .venv/bin/python
EMPS_LOG   ?= ../shared/data/emps/emps_estimation.csv
N          ?= 200
DL_N ?= 20
DL_N_VERIFY ?= 59
DL_N_NOMINAL ?= 150
DL_JOBS ?= 1
FUZZ_SECONDS ?= 600
MUTANTS_BUDGET ?= 3600
override MACHINE  := $(value MACHINE)
override LOG      := $(value LOG)
override OUT      := $(value OUT)
override MODEL    := $(value MODEL)
override EMPS_LOG := $(value EMPS_LOG)
override RADIUS_M := $(value RADIUS_M)
override FEED     := $(value FEED)
override DIR      := $(value DIR)
override PLANT    := $(value PLANT)
export BR_MK_MACHINE  := $(MACHINE)
export BR_MK_LOG      := $(LOG)
export BR_MK_OUT      := $(OUT)
export BR_MK_MODEL    := $(MODEL)
export BR_MK_EMPS_LOG := $(EMPS_LOG)
export BR_MK_RADIUS_M := $(RADIUS_M)
export BR_MK_FEED     := $(FEED)
export BR_MK_DIR      := $(DIR)
export BR_MK_PLANT    := $(or $(PLANT),offset=2.5)
export BR_MK_MAX_FEV  := $(value MAX_FEV)
# the counts: digits only (they are written into recipes)
_nodigits = $(subst 0,,$(subst 1,,$(subst 2,,$(subst 3,,$(subst 4,,$(subst 5,,$(subst 6,,$(subst 7,,$(subst 8,,$(subst 9,,$(1)))))))))))
_check_count = $(if $(value $(1)),$(if $(or $(call _nodigits,$(value $(1))),$(filter-out 1,$(words $(value $(1))))),$(error $(1) must be a whole number)))
$(foreach v,JOBS N SEED DIAGNOSE_FIRST DL_N DL_N_VERIFY DL_N_NOMINAL DL_JOBS FUZZ_SECONDS MUTANTS_BUDGET MAX_FEV,$(call _check_count,$(v)))
# The board whose firmware image `make firmware` / `make test` build and size:
# its CMakeLists (hal/<board>/) writes into <build>/board-<board>.txt the image's path, its
# part's flash size (KiB) and its RAM regions (NAME:ORIGIN:KiB).
BOARD      ?= stm32h7
ifneq ($(filter-out stm32h7 stm32g4,$(value BOARD))$(filter-out 1,$(words $(value BOARD))),)
  $(error BOARD must be stm32h7 or stm32g4)
endif
# `make firmware MACHINE=<file>` builds for another machine (docs/configure.md):
# its own cross build folder, build/<preset>-<name>-<hash> (firmware/design/build_dir.py:
# the first 8 hex digits of the SHA-256 of the file's real path, so that two files
# with the same "name" never share one), configured with -DBR_MACHINE, headers
# generated there. The folder is found inside the recipe, never while make parses.
# the cross preset of BOARD: stm32h7 (Cortex-M7) cm7-release, stm32g4 (Cortex-M4F) cm4-release
BOARD_PRESET = $(if $(filter stm32g4,$(BOARD)),cm4-release,cm7-release)
DEMO_OUT   := out/demo
ROBUST_OUT := out/robustness
HIDDEN_OUT := out/diagnose-hidden
TUNE_OUT   := out/tune
BENCH_OUT  := out/bench
DIAG_BENCH_OUT := out/diagnose-bench
TARGET_BENCH_OUT := out/target-bench
BENCH      := build/host-release/sim/br_bench

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

# $(call print_size,<build folder, a shell word>)
# Flash = text + data (the .data image is stored in flash); RAM per region
# (the board file <build>/board-BOARD.txt: the image, the flash KiB, then
# NAME:ORIGIN:KiB per RAM region) = the allocated sections whose address lies
# in it (.data, .bss, the reserved stack, NOLOAD sections), from arm-none-eabi-size -A.
define print_size
	$(Q)info=$(1)/board-$(BOARD).txt; \
	test -f "$$info" || { echo "no board $(BOARD) in the $(BOARD_PRESET) build ($$info)" >&2; exit 1; }; \
	read -r img fk regions < "$$info"; img=$$(realpath --relative-to=. "$$img"); \
	test -f "$$img" || { echo "no firmware image at $$img" >&2; exit 1; }; \
	arm-none-eabi-size "$$img" | awk 'NR == 2 { print $$1, $$2 }' | { read -r text data; \
	  f=$$((text + data)); echo "firmware $$img"; \
	  awk -v f=$$f -v t=$$text -v d=$$data -v fk=$$fk 'BEGIN { printf "  flash: %7d bytes (text %d + data %d)  %5.2f%% of %d KiB\n", f, t, d, 100 * f / (fk * 1024), fk }'; }; \
	for r in $$regions; do name=$${r%%:*}; rest=$${r#*:}; org=$${rest%%:*}; kib=$${rest#*:}; \
	  arm-none-eabi-size -A "$$img" | awk -v name=$$name -v org=$$((org)) -v kib=$$kib ' \
	    NF == 3 && $$3 ~ /^[0-9]+$$/ && $$3 + 0 >= org && $$3 + 0 < org + kib * 1024 && $$2 > 0 { b += $$2; s = s sprintf(" %s %d", $$1, $$2) } \
	    END { printf "  RAM %-8s %7d bytes (%s)  %5.2f%% of %d KiB\n", name ":", b, substr(s, 2), 100 * b / (kib * 1024), kib }' || exit 1; \
	done
endef

.PHONY: fuzz help deps build test demo bench target-bench pil target-chain diagnose validate diagnose-hidden diagnose-control diagnose-bench detection-limits firmware emps regen clean distclean robustness fleet mslip-plants

help:
	@echo "bristle targets:"
	@echo "  make deps      install Debian packages and the pinned .venv (cmake/setup-deps.sh)"
	@echo "  make build     configure + build host-debug (ASan + UBSan)"
	@echo "  make test      host-debug build + ctest, then the firmware image and its size"
	@echo "  make demo [RADIUS_M=m] [FEED=mm/min] [DIR=cw|ccw|both]  host-release build, run the circle demo into $(DEMO_OUT), its ISO 230-4 figures, plot it"
	@echo "  make bench     host-release build, time the PF (C and numpy) and the UKF, memory -> $(BENCH_OUT)/bench.json"
	@echo "  make diagnose LOG=<csv> OUT=<dir> [MACHINE=<json>]  what the model gets wrong in a measured log (docs/diagnose.md)"
	@echo "  make validate MODEL=<model.json> LOG=<csv>          a saved model's relerr on another log"
	@echo "  make diagnose-hidden  the hidden-cause suite -> docs/diagnose-hidden.md"
	@echo "  make diagnose-control the circle with the estimator on the nominal / extended model -> docs/diagnose-control.md"
	@echo "  make detection-limits smallest effect of each cause detected in 95 % of logs, false positives -> docs/detection-limits.md"
	@echo "  make diagnose-bench   peak memory of a diagnosis of a 2e6-row log written by br_simlog (docs/diagnose.md, Memory)"
	@echo "  make firmware [MACHINE=<json>] [BOARD=stm32g4]  cross build (cm7-release; BOARD=stm32g4: cm4-release; another machine: build/<preset>-<name>-<hash>), print the image's flash / RAM use (BOARD=$(BOARD))"
	@echo "  make emps      the EMPS drive through the chain: its log -> diagnose -> machine.json -> image -> tracking in the simulator -> $(EMPS_OUT), docs/machines/emps.md"
	@echo "  make robustness [N=200] [DIAGNOSE_FIRST=K]  Monte Carlo over N plants around the reference machine -> $(ROBUST_OUT), docs/robustness-results.md"
	@echo "  make mslip-plants [N=200]  every controller on N drawn Maxwell-slip plants -> $(MSLIP_OUT), docs/presliding-plants.md"
	@echo "  make fleet [N=200] [SEED=s]  N axes across the machine files a user may bring, each through the chain, every controller -> $(FLEET_OUT), docs/fleet.md"
	@echo "  make faults                 the fault campaign on the simulator (production guards) -> docs/reliability-faults.md"
	@echo "  make target-bench  instructions per PF particle-step / control period on QEMU's Cortex-M7 (and Cortex-M4: mps2-an386), flash / RAM; fails over target/mps2/budget.txt"
	@echo "  make pil       the circle with each estimator on QEMU's Cortex-M7 in lockstep with the host plant, compared bit for bit with the simulator (docs/link.md)"
	@echo "  make target-chain [PLANT='offset=2.5']  identification run over the link -> its log -> diagnose -> machine.json -> the images -> the circle in the loop before / after -> $(TC_OUT) (docs/link.md)"
	@echo "  make regen     regenerate everything generated from machines/reference.json (headers, tuning, golden traces)"
	@echo "  make tune [MACHINE=<json>] [MAX_FEV=n]  Nelder-Mead tuning of the PF and UKF noise (the reference: regenerates firmware/gen/bristle_gen/est/; another machine: its build folder's tune/, with tune/machine.json; docs/tuning.md)"
	@echo "  make figures   thesis Figs. 1-8 into docs/figures/ and docs/results.md (~12 min)"
	@echo "  make fuzz [FUZZ_SECONDS=600]  every libFuzzer target (clang, ASan + UBSan) for that long (ctest runs 20 s each)"
	@echo "  make mutants [MUTANTS_BUDGET=s]  the mutation check: C set + cosmic-ray on the diagnosis -> out/mutants (docs/mutants.md)"
	@echo "  make clean     remove build/ and out/ (distclean also removes .venv)"
	@echo "  V=1 shows the commands; JOBS=n sets the ctest parallelism (default 2)"

deps:
	$(Q)cmake/setup-deps.sh

build: deps
	$(call configure,host-debug)
	$(call build,host-debug)

# Every preset is built before ctest: the tests that run another preset's
# binary (regen_{pf,ukf}_tuned: the release tuner; target_qemu_replay: the
# mps2-an500 replay image, docs/target.md) build it through a ctest fixture,
# which then finds it up to date; the firmware image is sized at the end.
test: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(call configure,host-debug)
	$(call build,host-debug)
	$(call configure,cm7-release)
	$(call build,cm7-release)
	$(Q)echo "== test host-debug"
	$(Q)ctest --preset host-debug --output-on-failure -j$(JOBS)
	$(call print_size,build/$(BOARD_PRESET))
	$(Q)$(MAKE) firmware BOARD=stm32g4

# The circle (docs/circle-test.md): `make demo RADIUS_M=<m> FEED=<mm/min> DIR=cw|ccw|both`
# (br_demo_circle --radius-m, --feed-mm-min, --dir; each passed only when set,
# as data: the environment's BR_MK_*); then the ISO 230-4 figures into summary.json.
DEMO_ARGS = $${BR_MK_RADIUS_M:+"--radius-m=$$BR_MK_RADIUS_M"} $${BR_MK_FEED:+"--feed-mm-min=$$BR_MK_FEED"} \
  $${BR_MK_DIR:+"--dir=$$BR_MK_DIR"}
demo: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== demo -> $(DEMO_OUT)"
	$(Q)mkdir -p $(DEMO_OUT)
	$(Q)build/host-release/sim/br_demo_circle --out $(DEMO_OUT) $(DEMO_ARGS)
	$(Q)$(PYTHON) sim/plots/iso230_4.py $(DEMO_OUT)
	$(Q)MPLBACKEND=Agg $(PYTHON) sim/plots/plot_demo.py $(DEMO_OUT)

# Nelder-Mead tuning of the PF's and the UKF's noise variances on the circle
# (thesis section 3.2; br_tune_est --mslip-target adds the Maxwell-slip guard plants,
# docs/tuning.md, "Presliding that is not LuGre"): regenerates firmware/gen/bristle_gen/est/br_{pf,ukf}_tuned.h
# with the whole search (ctest regen_*_tuned checks only its checkpoint), the
# progress logs and thesis Fig. 1 in $(TUNE_OUT). docs/tuning.md.
# `make tune MACHINE=<file>` tunes another machine (docs/tuning.md, "Another
# machine"): a host-release build for it in its build folder (build_dir.py),
# the tuned headers, logs and a copy of the machine file with the tuned
# settings (tuned_machine.py) in <folder>/tune/, nothing in the source tree.
tune: deps
ifeq ($(MACHINE),)
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)mkdir -p $(TUNE_OUT)
	$(Q)build/host-release/sim/br_tune_est --est ukf --out firmware/gen/bristle_gen/est/br_ukf_tuned.h --log $(TUNE_OUT)/ukf.csv
	$(Q)build/host-release/sim/br_tune_est --est pf --out firmware/gen/bristle_gen/est/br_pf_tuned.h --log $(TUNE_OUT)/pf.csv
	$(Q)MPLBACKEND=Agg $(PYTHON) sim/plots/plot_tuning.py $(TUNE_OUT)/fig1_tuning.png $(TUNE_OUT)/pf.csv:"H-inf + PF" $(TUNE_OUT)/ukf.csv:"H-inf + UKF"
else
	$(Q)dir="$$($(PYTHON) firmware/design/build_dir.py host-release "$$BR_MK_MACHINE")"; abs="$$(realpath -- "$$BR_MK_MACHINE")"; \
	echo "== configure $$dir (BR_MACHINE=$$abs)"; \
	log="$$(cmake --preset host-release -B "$$dir" "-DBR_MACHINE=$$abs" 2>&1)" || { echo "$$log"; echo "configure $$dir failed" >&2; exit 1; }; \
	cmake --build "$$dir" --target br_tune_est $(NINJA_QUIET); \
	mkdir -p "$$dir/tune"; \
	"$$dir/sim/br_tune_est" --est ukf --out "$$dir/tune/br_ukf_tuned.h" --log "$$dir/tune/ukf.csv" $${BR_MK_MAX_FEV:+--max-fev "$$BR_MK_MAX_FEV"}; \
	"$$dir/sim/br_tune_est" --est pf --out "$$dir/tune/br_pf_tuned.h" --log "$$dir/tune/pf.csv" $${BR_MK_MAX_FEV:+--max-fev "$$BR_MK_MAX_FEV"}; \
	$(PYTHON) firmware/design/tuned_machine.py --machine "$$abs" --pf "$$dir/tune/br_pf_tuned.h" \
	  --ukf "$$dir/tune/br_ukf_tuned.h" --out "$$dir/tune/machine.json"
endif

# Thesis Figs. 1-8 into docs/figures/ and docs/results.md (about 12 min: the
# tunings, the sampling-time study, the demo; progress is printed).
figures: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)MPLBACKEND=Agg $(PYTHON) sim/studies/make_figures.py build/host-release out/figures

# C bench (records the input, times PF and UKF, memory), then the particles
# library's PF (installed by `deps`, sim/bench/requirements-particles.txt:
# nothing is installed here) and the numpy PF on the same recording; the numpy script prints the summary
# table and merges everything into bench.json. docs/bench.md.
bench: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== bench -> $(BENCH_OUT)"
	$(Q)mkdir -p $(BENCH_OUT)
	$(Q)$(BENCH) --json $(BENCH_OUT)/c.json --record $(BENCH_OUT)/pf_input.csv
	$(Q)build/host-release/sim/br_bench_link | tee $(BENCH_OUT)/link.txt
	$(Q)$(PYTHON) sim/bench/pf_particles.py $(BENCH_OUT)/pf_input.csv --out $(BENCH_OUT)/particles.json
	$(Q)$(PYTHON) sim/bench/pf_numpy.py $(BENCH_OUT)/pf_input.csv --c-json $(BENCH_OUT)/c.json \
	  --particles-json $(BENCH_OUT)/particles.json --out $(BENCH_OUT)/bench.json

# Instructions per PF particle-step and per control period on QEMU's emulated
# Cortex-M7 (-icount), flash / RAM from the map file. docs/target.md. Fails
# when a core's instructions per particle-step exceed its budget in
# target/mps2/budget.txt (target_bench.sh exits 1).
target-bench: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(call configure,cm7-release)
	$(call build,cm7-release)
	$(Q)echo "== target-bench -> $(TARGET_BENCH_OUT)"
	$(Q)target/mps2/target_bench.sh build/host-release build/cm7-release $(TARGET_BENCH_OUT)
	$(call configure,cm4-release)
	$(call build,cm4-release)
	$(Q)echo "== target-bench on the Cortex-M4 (mps2-an386) -> $(TARGET_BENCH_OUT)/m4"
	$(Q)BR_QEMU_MACHINE=mps2-an386 BR_BENCH_CPU=Cortex-M4 BR_BENCH_MHZ=170 \
	  target/mps2/target_bench.sh build/host-release build/cm4-release $(TARGET_BENCH_OUT)/m4

# The image in the loop (docs/link.md, "The image in the loop"): the thesis
# circle with each estimator, each axis's production application on QEMU's
# Cortex-M7 (br_pil_mps2) in lockstep with the host plant (br_pil), the duty
# sequences compared bit for bit with the simulator's same run; the demo's table.
pil: deps
	$(call configure,host-release)
	$(Q)cmake --build --preset host-release --target br_pil $(NINJA_QUIET)
	$(call configure,cm7-release)
	$(Q)cmake --build --preset cm7-release --target br_pil_mps2 $(NINJA_QUIET)
	$(Q)echo "== the circle in the loop (about 10 min)"
	$(Q)build/host-release/sim/br_pil --image build/cm7-release/target/mps2/br_pil_mps2.elf --est all --compare

# The chain on a running target (docs/link.md): an identification run of the
# production application over the link (br_link_sim, the plant with PLANT's
# cause) recorded by bristle-link -> make diagnose -> machine.json -> make
# firmware MACHINE= (the STM32H743 image and the image in the loop) -> the
# circle in the loop with the nominal and the diagnosed image (about 6 min).
TC_OUT := out/target-chain
target-chain: deps
	$(call configure,host-release)
	$(Q)cmake --build --preset host-release --target br_link_sim br_simlog br_pil $(NINJA_QUIET)
	$(call configure,cm7-release)
	$(Q)cmake --build --preset cm7-release --target br_pil_mps2 $(NINJA_QUIET)
	$(Q)rm -rf $(TC_OUT)
	$(Q)echo "== 1-2. the identification run over the link, recorded -> $(TC_OUT)/ident.csv"
	$(Q)PYTHONPATH=python $(PYTHON) sim/studies/target_chain.py ident --bin build/host-release/sim --work $(TC_OUT) \
	  --plant "$$BR_MK_PLANT"
	$(Q)echo "== 3. the diagnosis -> $(TC_OUT)/diagnose/machine.json"
	$(Q)$(MAKE) diagnose LOG=$(TC_OUT)/ident.csv OUT=$(TC_OUT)/diagnose MACHINE=machines/reference.json
	$(Q)echo "== 4. the images for the diagnosed machine"
	$(Q)$(MAKE) firmware BOARD=stm32h7 MACHINE=$(TC_OUT)/diagnose/machine.json
	$(Q)echo "== 5. the circle in the loop (H-inf + UKF): the nominal image, then the diagnosed one"
	$(Q)dir="$$($(PYTHON) firmware/design/build_dir.py cm7-release $(TC_OUT)/diagnose/machine.json)"; \
	PYTHONPATH=python $(PYTHON) sim/studies/target_chain.py circles --pil build/host-release/sim/br_pil \
	  --before build/cm7-release/target/mps2/br_pil_mps2.elf --after "$$dir/target/mps2/br_pil_mps2.elf" \
	  --work $(TC_OUT)/circle --plant "$$BR_MK_PLANT" --est ukf --diagnosis $(TC_OUT)/diagnose/machine.json

# Measured logs (docs/diagnose.md): diagnose one, validate a saved model on
# another, and the hidden-cause suite that writes docs/diagnose-hidden.md.
diagnose: deps
	$(Q)test -n "$$BR_MK_LOG" -a -n "$$BR_MK_OUT" || { echo "usage: make diagnose LOG=<csv> OUT=<dir> [MACHINE=<json>]" >&2; exit 2; }
	$(Q)PYTHONPATH=python MPLBACKEND=Agg $(PYTHON) -m bristle.diagnose diagnose "--log=$$BR_MK_LOG" "--out=$$BR_MK_OUT" \
	  $${BR_MK_MACHINE:+"--machine=$$BR_MK_MACHINE"}

validate: deps
	$(Q)test -n "$$BR_MK_MODEL" -a -n "$$BR_MK_LOG" || { echo "usage: make validate MODEL=<model.json> LOG=<csv>" >&2; exit 2; }
	$(Q)PYTHONPATH=python $(PYTHON) -m bristle.diagnose validate "--model=$$BR_MK_MODEL" "--log=$$BR_MK_LOG"

diagnose-control: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== diagnosis in control terms -> out/diagnose-control, docs/diagnose-control.md"
	$(Q)PYTHONPATH=python $(PYTHON) sim/studies/diagnose_control.py --bin build/host-release/sim --work out/diagnose-control \
	  --est ukf,pf --md docs/diagnose-control.md

# Peak RSS of a diagnosis of a 2 million-row log (br_simlog writes it, about
# 120 MB, into $(DIAG_BENCH_OUT)); goal under 1 GB. docs/diagnose.md, "Memory".
diagnose-bench: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== diagnosis memory benchmark -> $(DIAG_BENCH_OUT)"
	$(Q)$(PYTHON) sim/studies/diagnose_memory.py --simlog build/host-release/sim/br_simlog --work $(DIAG_BENCH_OUT) --rows 2000000

diagnose-hidden: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== hidden-cause suite -> $(HIDDEN_OUT), docs/diagnose-hidden.md"
	$(Q)mkdir -p $(HIDDEN_OUT)
	$(Q)pids=""; for k in 0 1; do \
	  $(PYTHON) tests/diagnose/hidden_cause.py --simlog build/host-release/sim/br_simlog --work $(HIDDEN_OUT) \
	    --shard $$k/2 --json $(HIDDEN_OUT)/shard$$k.json & pids="$$pids $$!"; done; \
	  rc=0; for p in $$pids; do wait $$p || rc=1; done; \
	  BR_HIDDEN_COMMAND="make diagnose-hidden" $(PYTHON) tests/diagnose/hidden_cause.py \
	    --merge $(HIDDEN_OUT)/shard0.json $(HIDDEN_OUT)/shard1.json --md docs/diagnose-hidden.md || rc=1; exit $$rc

# Detection limits (docs/detection-limits.md): per cause and noise level a bisection on a 15-size
# ladder with DL_N logs per probed size, the limit then proven with DL_N_VERIFY logs that must all
# detect the cause (59 of 59: a 95 % rate at 95 % confidence), and DL_N_NOMINAL nominal logs per
# noise level, on DL_JOBS processes (default one core: over an hour with the defaults;
# docs/detection-limits.md gives the wall time). DL_ prefix: N is the robustness study's.
detection-limits: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== detection limits -> out/detection-limits, docs/detection-limits.md"
	$(Q)OPENBLAS_NUM_THREADS=1 BR_DETECTION_COMMAND="make detection-limits DL_N=$(DL_N) DL_N_VERIFY=$(DL_N_VERIFY) DL_N_NOMINAL=$(DL_N_NOMINAL) DL_JOBS=$(DL_JOBS)" \
	  $(PYTHON) sim/studies/detection_limits.py --simlog build/host-release/sim/br_simlog --work out/detection-limits/logs \
	  --n $(DL_N) --n-verify $(DL_N_VERIFY) --n-nominal $(DL_N_NOMINAL) --jobs $(DL_JOBS) --md docs/detection-limits.md --png docs/detection-limits.png \
	  --json out/detection-limits/summary.json

# MACHINE reaches the recipe only as "$$BR_MK_MACHINE"; its build folder comes
# from build_dir.py (which validates the file first) inside the recipe.
MACHINE_DIR = "$$($(PYTHON) firmware/design/build_dir.py $(BOARD_PRESET) "$$BR_MK_MACHINE")"
firmware: deps
	$(Q)echo "== image for $(BOARD): the estimator the machine file's control.estimator gives"
	$(Q)$(PYTHON) firmware/design/image_info.py "$${BR_MK_MACHINE:-machines/reference.json}" "$(BOARD)"
ifeq ($(MACHINE),)
	$(call configure,$(BOARD_PRESET))
	$(call build,$(BOARD_PRESET))
	$(call print_size,build/$(BOARD_PRESET))
else
	$(Q)dir=$(MACHINE_DIR); abs="$$(realpath -- "$$BR_MK_MACHINE")"; \
	echo "== H-infinity synthesis for $$BR_MK_MACHINE ($$dir)"; \
	mkdir -p "$$dir/gen/bristle_gen/ctrl"; \
	$(PYTHON) firmware/design/synth_hinf.py "--machine=$$abs" "--out=$$dir/gen/bristle_gen/ctrl/br_hinf_gains.h"; \
	echo "== configure $$dir (BR_MACHINE=$$abs)"; \
	log="$$(cmake --preset $(BOARD_PRESET) -B "$$dir" "-DBR_MACHINE=$$abs" 2>&1)" || { echo "$$log"; echo "configure $$dir failed" >&2; exit 1; }; \
	echo "== build $$dir"; \
	cmake --build "$$dir" $(NINJA_QUIET)
	$(call print_size,$(MACHINE_DIR))
endif

# A real machine through the whole chain (docs/machines/emps.md): the EMPS
# log -> diagnosis -> machine.json -> its image -> its own reference
# trajectory on the identified plant with the log's PD, H-inf, H-inf + PF.
# EMPS_LOG (default ../shared/data/emps/emps_estimation.csv) reaches the
# recipes as "$$BR_MK_EMPS_LOG"; the image's folder is build_dir.py's for machine.json.
EMPS_OUT := out/emps-chain
emps: deps
	$(Q)$(MAKE) diagnose "LOG=$$BR_MK_EMPS_LOG" OUT=$(EMPS_OUT)/diagnose MACHINE=machines/emps.json
	$(Q)$(MAKE) firmware MACHINE=$(EMPS_OUT)/diagnose/machine.json
	$(Q)echo "== tracking on the simulator -> $(EMPS_OUT), docs/machines/emps.md"
	$(Q)dir="$$($(PYTHON) firmware/design/build_dir.py cm7-release $(EMPS_OUT)/diagnose/machine.json)"; \
	$(PYTHON) sim/studies/machine_chain.py --src . --work $(EMPS_OUT) --given machines/emps.json "--log=$$BR_MK_EMPS_LOG" \
	  --controller python/bristle/diagnose/machines/emps.json --cross "--cross-dir=$$dir" --track --circle \
	  --md docs/machines/emps.md > $(EMPS_OUT)/chain.log || { cat $(EMPS_OUT)/chain.log; exit 1; }
	$(Q)grep -E "tracking RMS|FAULT|^image|^circle" $(EMPS_OUT)/chain.log

# Everything generated from machines/reference.json (docs/machine-file.md):
# after editing it, `make regen` then `make test` needs no hand edits.
regen: deps
	$(Q)echo "== regen: machine parameters, estimator settings, gains, noise table, causes' table"
	$(Q)$(PYTHON) firmware/design/gen_machine.py
	$(Q)$(PYTHON) firmware/design/synth_hinf.py
	$(Q)$(PYTHON) firmware/design/gen_noise.py
	$(Q)$(PYTHON) firmware/design/gen_causes.py
	$(Q)echo "== regen: the link's message header and golden frames (docs/link.md)"
	$(Q)$(PYTHON) firmware/design/gen_link.py
	$(Q)$(PYTHON) tests/link/gen_golden.py
	$(Q)$(PYTHON) tests/rec/gen_rec_golden.py
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== regen: tuned estimator variances (about 5 min)"
	$(Q)build/host-release/sim/br_tune_est --est ukf --out firmware/gen/bristle_gen/est/br_ukf_tuned.h > /dev/null
	$(Q)build/host-release/sim/br_tune_est --est pf --out firmware/gen/bristle_gen/est/br_pf_tuned.h > /dev/null
	$(Q)echo "== regen: golden traces"
	$(Q)$(PYTHON) golden/gen_traces.py

# The libFuzzer targets of tests/fuzz for longer than ctest's 20 s each,
# corpora kept in out/fuzz (docs/reliability.md).
fuzz: deps
	$(call configure,fuzz)
	$(call build,fuzz)
	$(Q)for f in build/fuzz/tests/fuzz/fuzz_*; do \
	  n=$$(basename $$f); mkdir -p out/fuzz/$$n out/fuzz/$$n.findings; echo "== $$n for $(FUZZ_SECONDS) s"; \
	  $$f -max_total_time=$(FUZZ_SECONDS) -max_len=1024 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=out/fuzz/$$n.findings/ out/fuzz/$$n \
	    2>&1 | grep -E "^stat::number_of_executed_units|ERROR|SUMMARY"; \
	  test $${PIPESTATUS[0]} -eq 0; done

# Robustness study (docs/robustness.md): N plants drawn around the reference
# machine, every controller on each, all cores; DIAGNOSE_FIRST=K limits the
# identified-model runs (simulated identification log + diagnosis) to the first K.
robustness: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== robustness study, $(N) plants -> $(ROBUST_OUT), docs/robustness-results.md"
	$(Q)MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 $(PYTHON) sim/studies/robustness.py --bin build/host-release/sim --out $(ROBUST_OUT) \
	  --n $(N) $(if $(DIAGNOSE_FIRST),--diagnose-first $(DIAGNOSE_FIRST)) --md docs/robustness-results.md \
	  --command "make robustness N=$(N)$(if $(DIAGNOSE_FIRST), DIAGNOSE_FIRST=$(DIAGNOSE_FIRST))"

# The fault campaign (docs/reliability.md, "Fault campaign"): every injected
# fault and ordinary condition, each controller, on the reference machine's
# plants -> docs/reliability-faults.md; exits 1 on a bound broken that
# sim/studies/faults.sh does not list.
.PHONY: faults
faults: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== fault campaign -> docs/reliability-faults.md"
	$(Q)bash sim/studies/faults.sh build/host-release/sim/br_faults docs/reliability-faults.md

# The drawn Maxwell-slip plants (docs/presliding-plants.md, issue 30 item 5):
# every controller as shipped on N plants whose presliding is drawn; a stop is
# listed with its time and cause (the study's subject, hence --expect-faults).
MSLIP_OUT := out/mslip-plants
mslip-plants: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== drawn Maxwell-slip plants, $(N) plants -> $(MSLIP_OUT), docs/presliding-plants.md"
	$(Q)OPENBLAS_NUM_THREADS=1 $(PYTHON) sim/studies/mslip_plants.py --bin build/host-release/sim --out $(MSLIP_OUT) \
	  --n $(N) --jobs 2 --md docs/presliding-plants.md --command "make mslip-plants N=$(N)" --expect-faults

# The fleet study (docs/fleet.md): N axes drawn across the machine files a user
# may bring, each through the user's chain, every controller on its trajectory
# set, on Dask's local cluster of both cores; SEED the study's seed.
FLEET_OUT := out/fleet
SEED ?= 20261201
fleet: deps
	$(call configure,host-release)
	$(call build,host-release)
	$(Q)echo "== fleet study, $(N) axes -> $(FLEET_OUT), docs/fleet.md"
	$(Q)MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 $(PYTHON) sim/studies/fleet.py --out $(FLEET_OUT) --n $(N) --seed $(SEED) \
	  --workers 2 --md docs/fleet.md --command "make fleet N=$(N) SEED=$(SEED)"

# The mutation check (docs/mutants.md): every mutant of tests/mutants/ in
# scratch copies under build/mutants (the tree itself is never written),
# $(JOBS) at a time, within MUTANTS_BUDGET seconds -> out/mutants/summary.json, report.md.
.PHONY: mutants
mutants: deps
	$(Q)echo "== mutation check -> out/mutants (budget $(MUTANTS_BUDGET) s)"
	$(Q)$(PYTHON) tests/mutants/mutate.py --jobs $(JOBS) --budget $(MUTANTS_BUDGET) --work build/mutants --out out/mutants

clean:
	$(Q)rm -rf build out

distclean: clean
	$(Q)rm -rf .venv
