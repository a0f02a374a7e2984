"""The main window around the pages: menus, settings, its size on the screen and the measurements a crash left unfinished."""
