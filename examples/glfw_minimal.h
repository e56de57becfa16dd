/*
 * What glfw_minimal draws and glfw_minimal_check looks for: the colour of each
 * level of detail, and the shades of a box's faces. Flat colours without
 * lighting or blending, so that a screenshot holds exactly these values.
 */
#ifndef GLFW_MINIMAL_H
#define GLFW_MINIMAL_H

#define GLFW_MINIMAL_LEVELS 4

/* Coarsest first: red, orange, green, blue. */
static const unsigned char glfw_minimal_colour[GLFW_MINIMAL_LEVELS][3] = {
    {216, 48, 48}, {240, 160, 32}, {48, 184, 72}, {64, 112, 240}};

/* A face's colour is the level's times SHADE[face] / 4: the top, the faces
 * along x, the faces along z. */
static const unsigned char glfw_minimal_shade[3] = {4, 3, 2};

#endif /* GLFW_MINIMAL_H */
