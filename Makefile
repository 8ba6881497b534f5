# The two commands of the README's quick start: `make demo` and `make test`.
# Each bootstraps what it needs (system packages, .venv, pinned dependencies) first.
.PHONY: setup demo test bench clean

setup:
	@bash scripts/bootstrap.sh

demo: setup
	.venv/bin/lv3d demo --out out/demo

test: setup
	.venv/bin/python -m pytest -q tests

# every benchmark at a small size; `python -m benchmarks.run_all` without --quick runs the full sizes
bench: setup
	.venv/bin/python -m benchmarks.run_all --quick

clean:
	rm -rf out build dist *.egg-info
