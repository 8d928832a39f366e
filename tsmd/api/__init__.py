"""The local socket API: newline-delimited JSON on a Unix stream socket (docs/api.md)."""
