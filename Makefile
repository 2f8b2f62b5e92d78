# dcg-rig. The README's two commands: `make rig` and `make test`. Both install what is missing
# (apt, skipped when present) and build incrementally first.
SHELL := /bin/bash
BUILD ?= build
PYTHON := /usr/bin/python3
BLENDER ?= blender
JOBS ?= 2
MESH ?= data/spot.obj
MODEL := $(basename $(notdir $(MESH)))
OUT ?= out
CMAKE_FLAGS ?=
export DCG_MESHES ?= $(abspath ../shared/meshes)

.PHONY: all deps build build-rig rig test addon wheel extension bench bench-compare fuzz format clean

all: build

deps:
	@bash scripts/install-deps.sh

# Configure once (Ninja re-runs CMake by itself when a CMakeLists.txt changes), then build.
CONFIGURE = [ -f $(BUILD)/build.ninja ] || cmake -S . -B $(BUILD) -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=$(PYTHON) $(CMAKE_FLAGS)
build: deps
	@$(CONFIGURE)
	@cmake --build $(BUILD) -j$(JOBS)

# What rigging needs and nothing more (the engine, its module, the assembled add-on): no tests.
build-rig: deps
	@$(CONFIGURE)
	@cmake --build $(BUILD) --target python_package -j$(JOBS)

# Rig MESH (default: the bundled Spot) headlessly: out/<model>.blend, .glb, .fbx and .png.
rig: build-rig
	@mkdir -p $(OUT)
	DCG_PYTHONPATH=$(abspath $(BUILD))/python $(BLENDER) -b --factory-startup \
	  --python addon/dcg_rig/cli.py -- $(MESH) -o $(OUT)/$(MODEL).blend \
	  --glb $(OUT)/$(MODEL).glb --fbx $(OUT)/$(MODEL).fbx --png $(OUT)/$(MODEL).png

# clang-format (one pinned version, scripts/clang-format.sh) over the C++ sources; `make test`
# checks that nothing would change.
format:
	@bash scripts/clang-format.sh

# Every suite (ctest, pytest, Blender); one closing line "N passed, N failed, N skipped".
test: build extension
	@bash scripts/run-tests.sh $(BUILD)

# The engine's wheels (pyproject.toml), repaired by auditwheel so that they need nothing outside
# the manylinux policy: out/wheels/dcg-<version>-cp311-...whl (and cp313 where this machine has
# Python 3.13 with headers).
wheel: deps
	@bash scripts/build-wheels.sh $(OUT)/wheels

# The Blender 4.2+ extension with the wheels inside: out/dcg_rig-<version>.zip. Install it with
# Edit > Preferences > Get Extensions > Install from Disk, or
# `blender --command extension install-file -r user_default out/dcg_rig-<version>.zip`.
extension: wheel
	@$(PYTHON) scripts/make_extension.py --addon addon/dcg_rig --wheels $(OUT)/wheels \
	  --out-dir $(OUT) --license LICENSE

# The libFuzzer targets (tests/fuzz/: mesh readers, stage 0, the whole engine) for FUZZ_SECONDS
# in all, built with clang in build-fuzz/; `make test` runs them for 90 s. Crashing inputs: build-fuzz/artifacts/.
FUZZ_SECONDS ?= 600
fuzz: deps
	@FUZZ_KEEP_CORPUS=1 bash scripts/run-fuzz.sh $(FUZZ_SECONDS) $(BUILD)/test-results/fuzz-long.xml

# The legacy add-on zip for Blender 3.x, with the compiled module: out/dcg_rig.zip.
addon: build
	@mkdir -p $(OUT)
	@$(PYTHON) scripts/make_addon_zip.py $(BUILD)/blender_scripts/addons/dcg_rig $(OUT)/dcg_rig.zip

# Timings of every stage on every mesh of MESHES (folders or files), of the stress set (STRESS,
# written by scripts/make_stress_set.py) and of RIGGED, with CGAL's mean curvature flow skeleton
# as the baseline in the same run: out/bench/report.md (and results.jsonl), with each skeleton's
# quality (ends, joints, cycles, inside % for ours and MCF's, stability under rotation, scale,
# noise and another seed) and out/bench/contact_sheet.png (every mesh with its skeleton); per
# set, faces, parts, seconds, MCF's ratio, inside % by parts and the speed targets missed
# (out/bench/stress.md), the same as JSON (out/bench/summary.json); the
# whole pipeline on a 1.4M-face subdivided armadillo, time and peak RSS (out/bench/big.md);
# a live tau, Extractor.retune on hand, horse and quadruped-100k (out/bench/retune.md);
# then `dcg batch` models per minute with 1 and 2 workers: out/bench/batch.md; our skinning
# weights against Blender's bone heat on the same armatures (out/bench/weights.md, and spot at
# scales 0.01 and 100 in weights-scaled.md); on the artist-rigged characters of RIGGED, our
# skeleton's chamfer distances to the artists' (out/bench/rig-quality.md) and our weights and
# bone heat against the artists' weights on their skeletons (out/bench/weights-quality.md);
# which skeletons a noise of 1e-5 of the diagonal changes (out/bench/noise.md);
# last, `make bench-compare`. Not part of `make test`.
MESHES ?= ../shared/meshes
RIGGED ?= $(DCG_MESHES)/rigged
STRESS ?= $(OUT)/bench/stress
# The mesh files of MESHES (folders expanded), for the scripts that take files.
BENCH_FILES = $(sort $(foreach m,$(MESHES),$(if $(wildcard $(m)/.),$(wildcard $(addprefix $(m)/*.,obj off ply stl)),$(m))))
bench: build
	@cmake --build $(BUILD) --target dcg_bench -j$(JOBS)
	$(PYTHON) scripts/make_stress_set.py --out $(STRESS)
	$(PYTHON) scripts/bench.py --binary $(BUILD)/dcg_bench --pythonpath $(BUILD)/python \
	  --public $(DCG_MESHES) --out $(OUT)/bench/report.md $(MESHES) $(STRESS) $(RIGGED)
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/bench_big.py --mesh $(OUT)/bench/armadillo-1m.ply \
	  --out $(OUT)/bench/big.md
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/bench_retune.py --out $(OUT)/bench/retune.md \
	  $(DCG_MESHES)/hand.obj $(DCG_MESHES)/horse.ply $(STRESS)/quadruped-100k.ply
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/bench_batch.py --out $(OUT)/bench/batch.md $(MESHES)
	$(BLENDER) -b --factory-startup --python scripts/bench_weights.py -- --pythonpath $(BUILD)/python \
	  --out $(OUT)/bench/weights.md $(BENCH_FILES)
	$(BLENDER) -b --factory-startup --python scripts/bench_weights.py -- --pythonpath $(BUILD)/python \
	  --out $(OUT)/bench/weights-scaled.md --scale 0.01 --scale 100 data/spot.obj
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/bench_rig_quality.py --rigged $(RIGGED) \
	  --out $(OUT)/bench/rig-quality.md
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/bench_noise.py --public $(DCG_MESHES) \
	  --rigged $(RIGGED) --out $(OUT)/bench/noise.md
	$(BLENDER) -b --factory-startup --python-exit-code 1 --python scripts/bench_weights_quality.py \
	  -- --pythonpath $(BUILD)/python --rigged $(RIGGED) --out $(OUT)/bench/weights-quality.md
	$(PYTHON) scripts/bench_compare.py $(OUT)/bench/summary.json

# out/bench/summary.json (of `make bench`) against scripts/bench_reference.json: per mesh our
# time over MCF's in the same run, flagged when it grew by more than 25%; exit status 1 then.
# A new reference: cp out/bench/summary.json scripts/bench_reference.json.
bench-compare:
	$(PYTHON) scripts/bench_compare.py $(OUT)/bench/summary.json

clean:
	rm -rf $(BUILD) $(OUT)
