"""Running trained models with onnxruntime (no torch needed)."""
