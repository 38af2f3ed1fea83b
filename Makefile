# Fabric presets from the measurement sets (issue 3). Python from the project's virtualenv.
PYTHON ?= .venv/bin/python

.PHONY: presets measurements fit-table

# Regenerate every fabrics/*.toml with `catalog fit` (deterministic output), then the preset
# table of docs/fit.md made from them.
presets:
	$(PYTHON) tools/make_presets.py && $(PYTHON) -m catalog.bench.preset_table && $(PYTHON) tools/docs_figures.py

# Regenerate the gonio measurement sets (and dye spectra) from the yarn-level model.
measurements:
	$(PYTHON) tools/make_gonio.py

# The per-fabric HG vs Cook-Torrance error table of docs/fit.md.
fit-table:
	$(PYTHON) -m catalog.bench.fit_table && $(PYTHON) tools/docs_figures.py
