"""The conventions catalogue's demonstrations, one module per topic; the registry that names
them and runs them is :mod:`dyncheck.catalogue`."""
