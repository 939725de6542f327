from dyncheck.cli import console

raise SystemExit(console())
