# Writes the web app's index.html with the byte count of tetstream.wasm filled in (the page's
# progress bar needs the uncompressed size; a server may send the wasm compressed).
#   cmake -DIN=web/index.html -DOUT=build/web/index.html -DWASM=build/web/tetstream.wasm -P web_page.cmake
file(SIZE "${WASM}" wasm_bytes)
file(READ "${IN}" html)
string(REPLACE "@TETSTREAM_WASM_BYTES@" "${wasm_bytes}" html "${html}")
file(WRITE "${OUT}.tmp" "${html}")
file(RENAME "${OUT}.tmp" "${OUT}")
