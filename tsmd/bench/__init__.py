"""Benchmarks behind `tsmd bench NAME`: each prints figures; none asserts a timing."""
