"""Configuration: every pydantic model of a scenario and its parts, vessel model files, the
original simulator's SettingsConfig mapping. Validated before anything starts."""
