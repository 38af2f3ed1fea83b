"""Fabric catalog: woven-cloth transmission with fluorescence, rendered in real time.

Importing the package is cheap on purpose: no numpy-heavy or GL module is
imported here, so ``catalog --help`` answers at once. Parts:

- optics: :mod:`catalog.spectra`, :mod:`catalog.colorimetry`, :mod:`catalog.lights`,
  :mod:`catalog.fluorescence`, :mod:`catalog.btdf` (float64 numpy, no GL);
- :mod:`catalog.presets`: preset TOML <-> typed object;
- :mod:`catalog.cloth`, :mod:`catalog.render`, :mod:`catalog.viewer`;
- :mod:`catalog.cli`: the ``catalog`` command.
"""

import os
from pathlib import Path

__version__ = "0.1.0"

#: Repository root (the package is installed editable; shaders/ and fabrics/ live beside it).
PROJECT_ROOT = Path(__file__).resolve().parent.parent
SHADER_DIR = PROJECT_ROOT / "shaders"
FABRIC_DIR = PROJECT_ROOT / "fabrics"
#: Real measurements made by others, kept outside the project (see ../shared/data/README.md);
#: the environment variable CATALOG_SHARED_DATA points elsewhere (a checkout in another place).
SHARED_DATA_DIR = Path(os.environ.get("CATALOG_SHARED_DATA") or PROJECT_ROOT.parent / "shared" / "data")
