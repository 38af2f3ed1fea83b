import sys

from catalog.commands.cli import main

sys.exit(main())
