// Routes a response body through a chain of Transform streams before it reaches the socket, the
// way the expressjs `compression` middleware does it: res.write/res.end feed the first stream,
// 'drain' listeners on res (the backpressure of whatever pipes into res, e.g. serve-static's file
// stream) wait on the first stream, and the last stream's output goes to the real res.write,
// pausing while the socket is full. The handlers (serve-static, finalhandler) stay unaware.

export function tapBody(res, transforms) {
  if (!transforms.length) return;
  const write = res.write;
  const end = res.end;
  const on = res.on;
  const first = transforms[0];
  let last = first;
  for (const t of transforms.slice(1)) last = last.pipe(t);

  res.write = function tappedWrite(chunk, encoding, callback) {
    if (typeof encoding === 'function') [callback, encoding] = [encoding, undefined];
    if (chunk == null || chunk.length === 0) {
      if (callback) process.nextTick(callback);
      return true;
    }
    if (first.destroyed || first.writableEnded) return false;
    return first.write(chunk, encoding, callback);
  };
  res.end = function tappedEnd(chunk, encoding, callback) {
    if (typeof chunk === 'function') [callback, chunk, encoding] = [chunk, undefined, undefined];
    else if (typeof encoding === 'function') [callback, encoding] = [encoding, undefined];
    if (callback) on.call(res, 'finish', callback);
    if (!first.destroyed && !first.writableEnded) {
      if (chunk != null && chunk.length) first.write(chunk, encoding);
      first.end();
    }
    return this;
  };
  const addListener = function tappedOn(type, listener) {
    if (type === 'drain') {
      first.on('drain', listener);
      return this;
    }
    return on.call(this, type, listener);
  };
  res.on = res.addListener = addListener;

  last.on('data', (data) => {
    if (!write.call(res, data)) {
      last.pause();
      on.call(res, 'drain', function resume() {
        res.removeListener('drain', resume);
        last.resume();
      });
    }
  });
  last.on('end', () => end.call(res));
  // A client that goes away (or a fault that drops the socket) stops the chain and its timers.
  on.call(res, 'close', () => {
    for (const t of transforms) t.destroy();
  });
  for (const t of transforms) {
    t.on('error', (e) => {
      res.destroy(e);
    });
  }
}
