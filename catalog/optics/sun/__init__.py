"""The sun: solar position, the clear-sky direct and diffuse spectra (:mod:`.model`) and the
comparison with SPECTRL2 (:mod:`.spectrl2`)."""
