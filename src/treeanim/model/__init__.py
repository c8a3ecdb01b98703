"""What a tree is: hierarchy arrays, procedural generation, preset loading (no GL here)."""
