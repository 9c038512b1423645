# QuadCNN: `make demo` and `make test` do all set-up themselves (idempotent `make setup`).
SHELL := /bin/bash
.DEFAULT_GOAL := help

APT_PACKAGES := freecad-python3 xvfb xauth calculix-ccx
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
FREECAD_MOD := $(HOME)/.local/share/FreeCAD/Mod
OUT := out
export LANG := C.UTF-8
export QTWEBENGINE_CHROMIUM_FLAGS := --no-sandbox

.PHONY: help setup system-packages venv link demo test lint bench clean

help:
	@echo "make demo   - set up, then mesh a bundled example and write pictures to $(OUT)/"
	@echo "make test   - set up, then run ruff and the whole test suite"
	@echo "make setup  - install what is missing (Debian packages, $(VENV), FreeCAD Mod link)"
	@echo "make bench  - print speed and quality figures (background, field, mesh vs gmsh,"
	@echo "              onnxruntime inference, CalculiX plate-with-hole check)"

setup: system-packages $(STAMP) link

# Debian's FreeCAD 0.20.2 (its Python is /usr/bin/python3) and a virtual screen for GUI tests.
system-packages:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null \
	    | grep -q "install ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	    echo "installing Debian packages: $$missing"; \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q $$missing; \
	fi

# The venv shares FreeCAD's interpreter and its system numpy/scipy/matplotlib.
$(PY):
	/usr/bin/python3 -m venv --system-site-packages $(VENV)

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install -q --disable-pip-version-check -e ".[dev,train]"
	touch $(STAMP)

# Plain `freecadcmd` finds the workbench (and, through Init.py, the venv's packages).
link:
	@mkdir -p $(FREECAD_MOD)
	@if [ "$$(readlink -f $(FREECAD_MOD)/QuadCNN)" != "$$(pwd -P)" ]; then \
	    rm -rf $(FREECAD_MOD)/QuadCNN; ln -s "$$(pwd -P)" $(FREECAD_MOD)/QuadCNN; \
	    echo "linked $(FREECAD_MOD)/QuadCNN -> $$(pwd -P)"; fi

demo: setup
	@mkdir -p $(OUT)
	$(PY) -m quadcnn_wb background resources/examples/four_hole.json \
	    -o $(OUT)/four_hole_background.json --png $(OUT)/four_hole_background.png
	$(PY) -m quadcnn_wb field resources/examples/four_hole.json \
	    -o $(OUT)/four_hole_field.json --png $(OUT)/four_hole_field.png
	$(PY) -m quadcnn_wb mesh resources/examples/four_hole.json --method numerical \
	    -o $(OUT)/four_hole_mesh.json --png $(OUT)/four_hole_mesh.png
	$(PY) -m quadcnn_wb mesh resources/examples/four_hole.json --method numerical \
	    -o $(OUT)/four_hole_mesh.inp
	QUADCNN_OUT=$(OUT) freecadcmd quadcnn_wb/freecad/demo.py
	@echo "wrote $(OUT)/four_hole_{background,field,mesh}.png, their .json and four_hole_mesh.inp"
	@echo "and, from headless FreeCAD, $(OUT)/plate_design.FCStd (edited and regenerated),"
	@echo "plate_design_mesh.inp and plate_design_mesh.png"

lint: setup
	$(VENV)/bin/ruff check .

test: setup lint
	$(PY) -m pytest -q

# Speed figures (not part of the test suite).
bench: setup
	$(PY) -m quadcnn_wb.bench.background_speed
	$(PY) -m quadcnn_wb.bench.field_speed
	$(PY) -m quadcnn_wb.bench.mesh_vs_gmsh
	$(PY) -m quadcnn_wb.bench.inference_speed
	$(PY) -m quadcnn_wb.fem.plate_tension

clean:
	rm -rf $(OUT) .pytest_cache .ruff_cache
