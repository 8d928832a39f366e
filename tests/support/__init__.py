"""Fakes and helpers shared by the tests (no tests here): drives, plants, runners, profiles."""
