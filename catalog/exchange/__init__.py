"""Fabrics in and out of the catalog in the formats its users' tools already speak.

- :mod:`catalog.exchange.image_import`: a backlit scan or the design artwork of a lace -> a preset;
- :mod:`catalog.exchange.u3m`: U3M 1.0/1.1 (Vizoo/Browzwear's Unified 3D Material; ``.u3ma`` zipped) read,
  checked against the schema's required fields, and written (U3M 1.1);
- :mod:`catalog.exchange.gltf_export`: the draped curtain as glTF 2.0 binary (``.glb``);
- :mod:`catalog.exchange.imported_preset`: what both imports share: the lobes (from ``--gonio`` or the
  nearest catalog fabric) and the self-contained preset written atomically.
"""
