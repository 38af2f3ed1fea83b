# Fabric presets from the measurement sets (issue 3). Python from the project's virtualenv.
PYTHON ?= .venv/bin/python

.PHONY: presets measurements fit-table figures figures-age

# Regenerate every fabrics/*.toml with `catalog fit` (deterministic output), then the preset
# table of docs/fit.md made from them.
presets:
	$(PYTHON) tools/make_presets.py && $(PYTHON) -m benchmarks.preset_table && $(PYTHON) tools/docs_figures.py

# Regenerate the gonio measurement sets (and dye spectra) from the yarn-level model.
measurements:
	$(PYTHON) tools/make_gonio.py

# The per-fabric HG vs Cook-Torrance error table of docs/fit.md.
fit-table:
	$(PYTHON) -m benchmarks.fit_table && $(PYTHON) tools/docs_figures.py

# Measure every published result again (each bench module's full run, its JSON recording the
# commit and machine), then regenerate every table of the docs from the JSON. Hours on a
# 2-core machine; a module that needs what this machine lacks (the pathtrace extra, the
# validation data) stops the run with its one-line reason.
figures:
	for m in $$($(PYTHON) tools/figures_age.py --modules); do \
	  echo "figures: benchmarks.$$m"; $(PYTHON) -m benchmarks.$$m >/dev/null || exit 1; \
	done
	$(PYTHON) tools/docs_figures.py

# The published results older than the code they measure (a warning each; CI runs it).
figures-age:
	$(PYTHON) tools/figures_age.py
