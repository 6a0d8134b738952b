"""The compiled engine: its C sources and the Python that builds, keys and binds them."""
