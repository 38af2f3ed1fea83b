"""Measurement and fitting: gonio data (:mod:`.gonio`) and the eq. 7 fit (:mod:`.fitting`)."""
