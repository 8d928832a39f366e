import sys

from tsmd.cli import main

sys.exit(main())
