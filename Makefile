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

.PHONY: help setup system-packages venv link demo test lint bench learning-figures models \
	robustness families clean

help:
	@echo "make demo   - set up, then mesh a bundled example and write pictures to $(OUT)/"
	@echo "make test   - set up, then run ruff and the whole test suite"
	@echo "make setup  - install what is missing (Debian packages, $(VENV), FreeCAD Mod link)"
	@echo "make bench  - print speed and quality figures (background, field, mesh vs gmsh,"
	@echo "              onnxruntime inference, CalculiX plate-with-hole check)"
	@echo "make learning-figures - Table 2 of the paper with our models, cnn vs numerical"
	@echo "make models - regenerate the data sets and retrain the shipped models (hours)"
	@echo "make robustness - the 500-shape random robustness campaign"
	@echo "make families - 200 fresh random members of every shape family, numerical path"

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
	$(PY) -m quadcnn_wb mesh resources/examples/four_hole.json --method cnn \
	    -o $(OUT)/four_hole_mesh_cnn.json --png $(OUT)/four_hole_mesh_cnn.png
	QUADCNN_OUT=$(OUT) freecadcmd quadcnn_wb/freecad/demo.py
	@echo "wrote $(OUT)/four_hole_{background,field,mesh,mesh_cnn}.png, their .json and"
	@echo "four_hole_mesh.inp (mesh_cnn: streamlines from the shipped network, see 'fallback')"
	@echo "and, from headless FreeCAD, $(OUT)/plate_design.FCStd (edited and regenerated),"
	@echo "plate_design_mesh.inp and plate_design_mesh.png"

lint: setup
	$(VENV)/bin/ruff check .

# One worker per core (pytest-xdist); the FreeCAD tests share one worker (xdist_group).
test: setup lint
	$(PY) -m pytest -q -n auto --dist loadgroup

# Speed figures (not part of the test suite).
bench: setup
	$(PY) -m quadcnn_wb.bench.background_speed
	$(PY) -m quadcnn_wb.bench.field_speed
	$(PY) -m quadcnn_wb.bench.mesh_vs_gmsh
	$(PY) -m quadcnn_wb.bench.inference_speed
	$(PY) -m quadcnn_wb.fem.plate_tension

learning-figures: setup
	$(PY) -m quadcnn_wb.bench.table2 --samples 400
	$(PY) -m quadcnn_wb.bench.cnn_agreement --samples 40
	$(PY) -m quadcnn_wb.bench.inference_speed

# The exact commands behind resources/models (see docs/learning.md); needs the train extra.
models: setup
	@mkdir -p data
	$(PY) -m quadcnn_wb dataset concave -n 2000 --seed 1 --workers 2 -o data/concave.npz
	$(PY) -m quadcnn_wb dataset four_hole -n 2000 --seed 2 --workers 2 -o data/four_hole.npz
	$(PY) -m quadcnn_wb dataset semicircle -n 1200 --seed 3 --workers 2 -o data/semicircle.npz
	$(PY) -m quadcnn_wb train data/concave.npz -o resources/models/concave.onnx --recipe rays \
	    --epochs 5 --minutes 30 --threads 1 --seed 0
	$(PY) -m quadcnn_wb train data/four_hole.npz -o resources/models/four_hole.onnx \
	    --recipe rays --epochs 10 --minutes 45 --threads 1 --seed 0
	$(PY) -m quadcnn_wb train data/semicircle.npz -o resources/models/semicircle.onnx \
	    --recipe rays --epochs 10 --minutes 30 --threads 1 --seed 0

robustness: setup
	$(PY) -m quadcnn_wb.bench.robustness -n 500 --seed 0

clean:
	rm -rf $(OUT) .pytest_cache .ruff_cache

families: setup
	$(PY) -m quadcnn_wb.bench.families -n 200 --workers 2
