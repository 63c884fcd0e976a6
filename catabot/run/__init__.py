"""The run shell: the `catabot` command, the launcher, the conductor and service programs,
progress and the end-of-run summary."""
