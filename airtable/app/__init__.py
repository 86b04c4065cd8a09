"""The desktop app: window, drawing, input, the game loop and demo loading (the only pygame users)."""
