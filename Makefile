# Two commands: `make run` plays the bundled sample scene, `make test` runs the tests.
# Both build .venv from nothing the first time, from requirements.lock (exact versions and
# hashes, installed by uv), and again whenever the lock changes.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
PY     := $(VENV)/bin/python
UV     := $(VENV)/bin/uv
STAMP  := $(VENV)/.installed
LOCK   := requirements.lock
# uv at the version the lock names (the lock installs it too; this is only the bootstrap)
UV_VERSION := $(shell sed -n 's/^uv==\([^ ]*\).*/\1/p' $(LOCK))
# The platform the lock is for: CPython 3.11 on Linux x86-64 (glibc 2.28 or newer)
LOCK_TARGET := --python-version 3.11 --python-platform x86_64-manylinux_2_28
LATEST := .venv-latest

# Prints each package whose newest release differs from the lock (what test-latest tries).
define LOCK_DRIFT
import importlib.metadata as md, re, sys
pins = re.findall(r"^([A-Za-z0-9._-]+)==(\S+)", open(sys.argv[1]).read(), re.M)
for name, pinned in pins:
    try:
        now = md.version(name)
    except md.PackageNotFoundError:
        continue
    if now != pinned:
        print(f"  newer than the lock: {name} {pinned} -> {now}")
endef
export LOCK_DRIFT

.PHONY: run test test-all test-latest bench lock docs lint clean ambf parity ros

$(UV):
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check "uv==$(UV_VERSION)"

# Bytecode compiled at install (uv does not by default): where Python may not write it
# (PYTHONDONTWRITEBYTECODE, a read-only venv) every command would compile its imports again,
# ~0.6 s of `adfkit validate`'s 1.3 s on the corpus.
$(STAMP): $(LOCK) | $(UV)
	$(UV) pip sync --quiet --python $(PY) --require-hashes --compile-bytecode $(LOCK)
	$(UV) pip install --quiet --python $(PY) --no-deps --no-build-isolation -e .
	$(PY) -m compileall -q -j 0 adfkit
	@touch $(STAMP)

run: $(STAMP)
	$(PY) -m adfkit demo

test: $(STAMP)
	$(PY) -m pytest -q

test-all: $(STAMP)
	$(PY) -m pytest -q -m ''

# The same suite against the newest releases pyproject.toml allows, in a venv of its own:
# drift in a dependency shows here on purpose before a user meets it.
test-latest: | $(UV)
	rm -rf $(LATEST)
	$(UV) venv --quiet --python $(PYTHON) $(LATEST)
	$(UV) pip install --quiet --python $(LATEST)/bin/python --refresh --upgrade -e '.[all,test,dev]'
	@$(LATEST)/bin/python -c "$$LOCK_DRIFT" $(LOCK)
	$(LATEST)/bin/python -m pytest -q

# Re-resolve the lock to the newest releases pyproject.toml allows (then run `make test`).
lock: | $(UV)
	$(UV) pip compile pyproject.toml --extra all --extra test --extra dev $(LOCK_TARGET) --generate-hashes --upgrade \
		--quiet -o $(LOCK)

# The documentation site (docs/, API reference from the docstrings) in site/; strict: a broken
# link, anchor or reference fails (not --quiet: at its quiet level mkdocs drops the warnings
# that strict mode counts, and a broken anchor passed).
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

# The project's habits, as CI checks them: ruff's lint rules and its format, the type check.
lint: $(STAMP)
	$(VENV)/bin/ruff check --quiet .
	$(VENV)/bin/ruff format --check --quiet .
	$(VENV)/bin/mypy

# AMBF 2.0 itself, built headless once from ../shared/ambf into the cache (outside the
# checkout; a no-op when it is there), and adfkit's AMBF plugin built against it: what
# `adfkit parity` plays scenes in. `make parity` runs the parity tests, the slow ones too.
AMBF_KIT   ?= ../shared/ambf
AMBF_CACHE ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/adfkit/ambf-build
ambf: $(STAMP)
	@if [ -x "$(AMBF_CACHE)/ambf/bin/lin-x86_64/ambf_simulator" ] && [ -f "$(AMBF_CACHE)/ambf/build/AMBFConfig.cmake" ]; then \
		echo "AMBF is built: $(AMBF_CACHE)/ambf"; \
	elif [ -f "$(AMBF_KIT)/build_ambf_headless.sh" ]; then \
		bash "$(AMBF_KIT)/build_ambf_headless.sh" "$(abspath $(AMBF_KIT))/ambf-2.0-src.tar.gz" "$(AMBF_CACHE)" 2; \
	else \
		echo "no AMBF kit at $(AMBF_KIT) (AMBF_KIT=DIR names one) and no build in $(AMBF_CACHE)"; exit 1; \
	fi
	@$(PY) -c "from adfkit.parity import ambf; print('adfkit AMBF plugin:', ambf.plugin_library(ambf.find_build('$(AMBF_CACHE)/ambf')))"

parity: ambf
	ADFKIT_AMBF="$(AMBF_CACHE)/ambf" $(PY) -m pytest -q -m '' tests/test_parity*.py

# ROS 1 from Debian's packages for `adfkit ros` and its tests (adfkit/ros/env.py names them): installed
# where this runs as root with apt, else the command to run is printed. Without them the ROS
# tests skip and nothing else changes.
ros: $(STAMP)
	@debs="$$($(PY) -c 'from adfkit.ros.env import DEBIAN_PACKAGES; print(*DEBIAN_PACKAGES)')"; \
	if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$debs; \
	else \
		echo "ROS 1 for adfkit ros: run as root: apt-get install $$debs"; exit 1; \
	fi

bench: $(STAMP)
	@for b in bench/*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) $(LATEST) site build dist *.egg-info .pytest_cache
