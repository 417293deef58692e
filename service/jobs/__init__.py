"""Long work as persisted jobs: an SQLite store and a process pool that runs them (api.md)."""
