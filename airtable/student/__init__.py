"""The student's window and the `airtable-client` command: a sibling of the teacher's app."""
