# `make run` and `make test` do all set-up on a fresh machine (Python >= 3.11 needed).
VENV ?= .venv
PYTHON ?= python3
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp

.PHONY: setup run test lint bench clean

$(STAMP): pyproject.toml scripts/system-deps.sh
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "CataBot needs Python >= 3.11"'
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	@# a venv made before open3d-cpu: the two share files, so the full build leaves first
	if [ "$$(uname -sm)" = "Linux x86_64" ] && $(PY) -m pip show -q open3d 2>/dev/null; then \
		$(PY) -m pip uninstall -q -y open3d; fi
	$(PY) -m pip install -q -e ".[dev]"
	bash scripts/system-deps.sh
	@# numba's cache of the compiled kernels, three processes side by side (20 s → 10 s)
	$(PY) -c "from services.sensors.wave_pass import warm_up; warm_up()" & a=$$!; \
	$(PY) -c "from services.physics.kernels import warm_up; warm_up()" & b=$$!; \
	$(PY) -c "from services.physics import wave_pull, wet; wet.warm_up(); wave_pull.warm_up()" \
		&& wait $$a && wait $$b
	touch $(STAMP)

setup: $(STAMP)
	@# every process of a run imports the package afresh: its bytecode is compiled here once,
	@# for shells with PYTHONDONTWRITEBYTECODE set, which else compile it in every process
	@# (0.6 s of CPU a run of four processes, a quarter of their start)
	@$(PY) -m compileall -q catabot services

run: setup
	$(VENV)/bin/catabot run

lint: setup
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy

test: lint
	@# a worker a core and one more (8 at most), each test module on one (its module fixtures
	@# built once): the end-to-end runs wait on their clocks and leases much of the time, so
	@# the extra worker fills idle cores (2 cores: 527 s with two workers, 441 s with three)
	$(PY) -m pytest -q -n $$(( $$(nproc) < 7 ? $$(nproc) + 1 : 8 )) --dist loadscope

bench: setup
	$(PY) -m benchmarks

clean:
	rm -rf $(VENV) runs .mypy_cache .ruff_cache .pytest_cache
