"""Optics: spectra, colorimetry, lights, fluorescence, the BTDF, the float64 per-pixel
shading reference, the sun (:mod:`.sun`) and bispectral matrices (:mod:`.bispectral`).
float64 numpy only; never imports GL, the renderer or the viewer."""
