import sys

from reactmocap.cli import main

sys.exit(main())
