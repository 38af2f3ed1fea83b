"""Measured bispectral (Donaldson) matrices: reading, the separable fit (:mod:`.matrix`) and
the study of fluorescence representations on them (:mod:`.study`)."""
