"""Built-in demos: one file each (see airtable/app/demo_loader.py). Copy one to start your own."""
