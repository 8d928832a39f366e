"""One module per ``tsmd`` subcommand; each is thin and calls into the library."""
