# Two set-up commands for a fresh machine (each installs what it needs):
#   make demo   a demo pipeline on the embedded sample files
#   make test   the test suite
PYTHON ?= python3
VENV ?= .venv
BIN = $(VENV)/bin
DEMO = build/demo

.PHONY: demo test bench fuzz clean

$(BIN)/.installed: setup.cfg pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

demo: $(BIN)/.installed
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
	@echo '$$ rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --seed 1 | rough resample --spacing 0.1545mm | rough fit-fractal'
	@$(BIN)/rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --seed 1 | $(BIN)/rough resample --spacing 0.1545mm | $(BIN)/rough fit-fractal
	@echo
	@echo '$$ rough synth --size 512x512 --spacing 10um --anisotropy 2.2,1um,2.5,3um,30 --seed 1 | rough rose --step 30 --plot $(DEMO)/rose.png'
	@$(BIN)/rough synth --size 512x512 --spacing 10um --anisotropy 2.2,1um,2.5,3um,30 --seed 1 | $(BIN)/rough rose --step 30 --plot $(DEMO)/rose.png
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

test: $(BIN)/.installed
	$(BIN)/python -m pytest -q

bench: $(BIN)/.installed
	$(BIN)/python bench/bench_io.py
	$(BIN)/python bench/bench_metrology.py
	$(BIN)/python bench/bench_fractal.py
	$(BIN)/python bench/bench_render.py
	$(BIN)/python bench/bench_tip.py

fuzz: $(BIN)/.installed
	$(BIN)/python -m pip install --quiet -e '.[fuzz]'
	$(BIN)/python bench/fuzz_readers.py -runs=1000000 -max_len=8192 -timeout=10

clean:
	rm -rf build $(VENV) *.egg-info .pytest_cache .hypothesis
