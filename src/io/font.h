/* The one bitmap font of the program's pictures: the keys of `pfsph render`'s previews
 * (src/io/render_key.c) and the live viewer's overlay (src/view/draw.c). */
#ifndef PFSPH_IO_FONT_H
#define PFSPH_IO_FONT_H

/* Glyphs are 3x5 pixels, drawn 4 apart; upper case, digits and the punctuation the keys and the
 * overlay use (lower case is drawn as upper case). */
#define PFSPH_FONT_W 3
#define PFSPH_FONT_H 5
#define PFSPH_FONT_ADVANCE 4

/* The glyph of c: 15 characters, 5 rows of 3 from the top left, '#' lit; NULL when the font has
 * no such character (drawn as a space). */
const char *pfsph_font_glyph(char c);

#endif
