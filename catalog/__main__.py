import sys

# the signal handlers before anything heavy is imported: a SIGTERM during start-up then
# exits 143 like one during the work (catalog.core.atomic.install_signal_handlers)
from catalog.core.atomic import install_signal_handlers

install_signal_handlers()

from catalog.commands.cli import main  # noqa: E402

sys.exit(main())
