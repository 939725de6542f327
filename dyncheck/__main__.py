from dyncheck.cli import main

raise SystemExit(main())
