import sys

from strapdown.cli import main

sys.exit(main())
