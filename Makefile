# Two set-up commands for a fresh machine (each installs what it needs):
#   make demo   a demo pipeline on the embedded sample files
#   make test   the test suite
# Both build the wheel and install it (not editable, with every extra) into .venv, so they
# run what a user installs; the wheel is rebuilt whenever a source file changes.
PYTHON ?= python3
VENV ?= .venv
BIN = $(VENV)/bin
DEMO = build/demo
SOURCES = setup.cfg pyproject.toml LICENSE README.md $(shell find rough sample_profiles -name '*.py' -o -name '*.tsv' -o -name '*.x3p' -o -path '*/templates/*')

.PHONY: demo demo-pipeline test lint format docs wheel install-wheel bench bench-run fuzz clean

$(BIN)/.installed: $(SOURCES)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	flock $(VENV)/.install-lock $(MAKE) --no-print-directory install-wheel
	touch $@

# one at a time (flock above): parallel runs would share dist/ and build/
install-wheel:
	$(BIN)/python -m pip install --quiet --upgrade pip setuptools wheel
	$(BIN)/python -m pip uninstall --quiet --yes rough 2>/dev/null || true  # the distribution's name up to 0.1.0
	rm -rf dist build/lib build/bdist.*
	$(BIN)/python -m pip wheel --quiet --no-deps --no-build-isolation --wheel-dir dist .
	$(BIN)/python -m pip install --quiet "$$(ls dist/rough_metrology-*.whl)[all,test,lint,docs]"
	$(BIN)/python -m pip install --quiet --no-deps --force-reinstall dist/rough_metrology-*.whl

wheel: $(BIN)/.installed

demo: $(BIN)/.installed
	$(MAKE) --no-print-directory demo-pipeline BIN=$(BIN)

# the pipeline alone, with the rough installed in $(BIN) (.ci/run points it at a fresh install)
demo-pipeline:
	@mkdir -p $(DEMO)
	@echo '$$ rough info sample_profiles/rock-profile.tsv'
	@$(BIN)/rough info sample_profiles/rock-profile.tsv
	@echo
	@echo '$$ rough convert sample_profiles/rock-profile.tsv -o $(DEMO)/rock-profile.x3p'
	@$(BIN)/rough convert sample_profiles/rock-profile.tsv -o $(DEMO)/rock-profile.x3p
	@echo '$$ cat $(DEMO)/rock-profile.x3p | rough convert -f gsf | rough info'
	@cat $(DEMO)/rock-profile.x3p | $(BIN)/rough convert -f gsf | $(BIN)/rough info
	@echo
	@echo '$$ rough info --json sample_profiles/rock-map.x3p   (selected keys)'
	@$(BIN)/rough info --json sample_profiles/rock-map.x3p | $(BIN)/python -c "import json,sys; d=json.load(sys.stdin); print({k: d[k] for k in ('shape', 'spacing', 'valid_points', 'Sq')})"
	@echo
	@echo '$$ rough detrend sample_profiles/rock-profile.tsv | rough features --list $(DEMO)/features.tsv --plot $(DEMO)/profile.png'
	@$(BIN)/rough detrend sample_profiles/rock-profile.tsv | $(BIN)/rough features --list $(DEMO)/features.tsv --plot $(DEMO)/profile.png
	@echo
	@echo '$$ rough features sample_profiles/rock-map.x3p'
	@$(BIN)/rough features sample_profiles/rock-map.x3p
	@echo
	@echo '$$ rough fit-fractal --plot $(DEMO)/psd.png sample_profiles/rock-profile.tsv'
	@$(BIN)/rough fit-fractal --plot $(DEMO)/psd.png sample_profiles/rock-profile.tsv
	@echo
	@echo '$$ rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --seed 1 | rough resample --step 0.1545mm | rough fit-fractal'
	@$(BIN)/rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --seed 1 | $(BIN)/rough resample --step 0.1545mm | $(BIN)/rough fit-fractal
	@echo
	@echo '$$ rough synth --size 512x512 --step 10um --anisotropy 2.2,1um,2.5,3um,30 --seed 1 | rough rose --angle-step 30 --plot $(DEMO)/rose.png'
	@$(BIN)/rough synth --size 512x512 --step 10um --anisotropy 2.2,1um,2.5,3um,30 --seed 1 | $(BIN)/rough rose --angle-step 30 --plot $(DEMO)/rose.png
	@echo
	@echo '$$ rough render --speed 20mm/s --speed 120mm/s --plot $(DEMO)/forces.png sample_profiles/rock-profile.tsv   (the simulated hand)'
	@$(BIN)/rough render --speed 20mm/s --speed 120mm/s --plot $(DEMO)/forces.png sample_profiles/rock-profile.tsv
	@echo
	@rm -rf $(DEMO)/study
	@echo '$$ rough experiment design --preset costa2000 --subjects 6 --seed 1 $(DEMO)/study'
	@$(BIN)/rough experiment design --preset costa2000 --subjects 6 --seed 1 $(DEMO)/study
	@echo '$$ rough experiment run $(DEMO)/study --subject S0N --observer rq=12,dimension=-4,spread=0.5   (N = 1 … 6, headless)'
	@for s in S01 S02 S03 S04 S05 S06; do $(BIN)/rough experiment run $(DEMO)/study --subject $$s --observer rq=12,dimension=-4,spread=0.5; done
	@echo '$$ rough experiment analyze $(DEMO)/study --set 1 --plot $(DEMO)/figure4.png'
	@$(BIN)/rough experiment analyze $(DEMO)/study --set 1 --plot $(DEMO)/figure4.png

# PYTHONSAFEPATH keeps the source tree off sys.path: the tests import the installed wheel
test: $(BIN)/.installed
	PYTHONSAFEPATH=1 $(BIN)/python -m pytest -q

lint: $(BIN)/.installed
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python .ci/check_version.py

format: $(BIN)/.installed
	$(BIN)/ruff check --fix .
	$(BIN)/ruff format .

docs: $(BIN)/.installed
	rm -rf build/docs docs/auto_examples
	PATH="$(abspath $(BIN)):$$PATH" PYTHONSAFEPATH=1 $(BIN)/python -m sphinx -W --keep-going -q -b html docs build/docs
	@echo "documentation: build/docs/index.html"

# every benchmark, paired with its baseline; the README's table is written from their figures
bench: $(BIN)/.installed
	@mkdir -p build && rm -f build/bench.jsonl
	ROUGH_BENCH_RESULTS=build/bench.jsonl $(MAKE) --no-print-directory bench-run BIN=$(BIN)
	$(BIN)/python bench/table.py build/bench.jsonl README.md

bench-run:
	$(BIN)/python bench/bench_startup.py
	$(BIN)/python bench/bench_io.py
	$(BIN)/python bench/bench_metrology.py
	$(BIN)/python bench/bench_fractal.py
	$(BIN)/python bench/bench_render.py
	$(BIN)/python bench/bench_tip.py
	$(BIN)/python bench/bench_scaling.py
	$(BIN)/python bench/bench_batch.py
	$(BIN)/python bench/bench_tribology.py

fuzz: $(BIN)/.installed
	$(BIN)/python -m pip install --quiet atheris
	$(BIN)/python bench/fuzz_readers.py -runs=1000000 -max_len=8192 -timeout=10

clean:
	rm -rf build dist $(VENV) *.egg-info .pytest_cache .hypothesis docs/auto_examples
