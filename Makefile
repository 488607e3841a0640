# make demo : set up .venv, simulate two rolls on a shipped part with the paper's noise, localize; then roll
#             reactively on the bracket drawn in CAD, a 5 mm wheel from inside the kidney's concave waist, and the
#             straight jaw over a burr the kidney's model does not have (plots in out/)
# make test : set up .venv; lint (ruff), type-check (mypy), run the tests and the doctests (two processes, a test
#             file to each at a time) and the benchmark smoke run (two processes too)
PYTHON ?= python3.11
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench bench-compare bench-baseline march-report passivity-report clean

$(STAMP): pyproject.toml
	@test -x $(PY) || { command -v $(PYTHON) >/dev/null 2>&1 || { echo "$(PYTHON) not found; run: make PYTHON=/path/to/python3.11"; exit 1; }; $(PYTHON) -m venv $(VENV); }
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	@# numba's kernels compiled once into its cache, not by each process of the first commands and tests
	$(PY) -c "import driver; print(f'compiled the kernels in {driver.compile_kernels():.1f} s')"
	@touch $(STAMP)

demo: $(STAMP)
	@mkdir -p out
	$(VENV)/bin/rolltouch simulate parts/trefoil.json --start 120 --roll 20 --roll 15 --noise paper --engine pymunk --out out/demo.npz --plot out/demo.png
	$(VENV)/bin/rolltouch locate out/demo.npz --part parts/trefoil.json
	$(VENV)/bin/rolltouch simulate parts/bracket.dxf --start 75 --reactive --noise paper --seed 2 --out out/demo-cad.npz --plot out/demo-cad.png
	$(VENV)/bin/rolltouch simulate parts/kidney.csv --jaw wheel:5 --start 66 --reactive --noise paper --seed 2 --out out/demo-wheel.npz --plot out/demo-wheel.png
	$(VENV)/bin/rolltouch simulate parts/bracket.dxf --jaw wheel:5 --start 163 --reactive --noise paper --seed 2 --out out/demo-wheel-cad.npz --plot out/demo-wheel-cad.png
	@# a burr where the jaw rolls: the run ends MODEL MISMATCH, exit status 2 (expected here)
	$(VENV)/bin/rolltouch simulate parts/kidney.csv --start 40 --reactive --world parts/burr.toml --noise paper --seed 1 --engine kinematic --out out/demo-burr.npz --plot out/demo-burr.png; test $$? -eq 2

CODE   := localizer passivity sim2d driver bench tests

test: $(STAMP)
	$(VENV)/bin/ruff check $(CODE)
	$(VENV)/bin/ruff format --check $(CODE)
	$(VENV)/bin/mypy
	$(PY) -m pytest -q -n 2 --dist loadfile tests localizer passivity sim2d driver
	$(PY) -m pytest -q -n 2 bench --benchmark-disable -p no:cacheprovider

# Regression runs against the committed baseline (bench/baseline/<machine>/0001_baseline.json), on
# the fastest round of each benchmark. BENCH_FAIL is the allowed slow-down: this 2-core machine's
# own spread between back-to-back runs reached 58% (docs/contributing.md, "Benchmark regressions").
BENCH_STORE := file://bench/baseline
BENCH_OPTS  := --benchmark-only --benchmark-max-time=2 -p no:cacheprovider
BENCH_FAIL  ?= min:75%

bench: $(STAMP)
	@mkdir -p out
	$(PY) -m pytest bench $(BENCH_OPTS) --benchmark-json=out/bench.json

bench-compare: $(STAMP)
	@mkdir -p out
	@ls bench/baseline/*/0001_baseline.json >/dev/null 2>&1 || { echo "no baseline under bench/baseline: run 'make bench-baseline' on the commit to compare against"; exit 1; }
	$(PY) -m pytest bench $(BENCH_OPTS) --benchmark-storage=$(BENCH_STORE) --benchmark-compare=0001 \
		--benchmark-compare-fail=$(BENCH_FAIL) --benchmark-json=out/bench.json

bench-baseline: $(STAMP)
	rm -rf bench/baseline
	$(PY) -m pytest bench $(BENCH_OPTS) --benchmark-storage=$(BENCH_STORE) --benchmark-save=baseline

passivity-report: $(STAMP)
	$(PY) -m bench.reports.passivity --out docs/generated/passivity

march-report: $(STAMP)
	$(PY) -m bench.reports.march_study --out docs/generated/march

clean:
	rm -rf $(VENV) out .pytest_cache .benchmarks
