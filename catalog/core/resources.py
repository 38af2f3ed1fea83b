"""Where the project's files are: shaders, the fabric catalog and the validation data.

In a checkout (editable install) ``shaders/`` and ``fabrics/`` are the top-level folders
beside the package. The measured validation data is not part of the project; it is looked
for beside the checkout.
"""

import os
from pathlib import Path

#: Repository root (the package is installed editable; shaders/ and fabrics/ live beside it).
PROJECT_ROOT = Path(__file__).resolve().parent.parent.parent
SHADER_DIR = PROJECT_ROOT / "shaders"
FABRIC_DIR = PROJECT_ROOT / "fabrics"
#: Environment variable naming the validation data folder (overrides the default below).
DATA_ENV = "CATALOG_DATA"
#: Real measurements made by others, not shipped with the project: $CATALOG_DATA, else
#: shared/data beside the checkout.
SHARED_DATA_DIR = (Path(os.environ[DATA_ENV]).expanduser() if os.environ.get(DATA_ENV)
                   else PROJECT_ROOT.parent / "shared" / "data")
