// The page's download rate (web/rate.js), fed with times given by the test.
import assert from 'node:assert/strict';
import test from 'node:test';
import { RateMeter } from '../../web/rate.js';

test('the rate follows the bytes over the window and drops to 0 when nothing comes', () => {
  const meter = new RateMeter();
  // 100 KB/s for 3 s, reported every 50 ms.
  for (let ms = 0; ms <= 3000; ms += 50) meter.add(ms, ms * 100);
  assert.ok(Math.abs(meter.bytesPerSecond(3000) - 100000) <= 5000, `${meter.bytesPerSecond(3000)}`);
  assert.equal(meter.bytesPerSecond(6000), 0, 'no bytes for 3 s: no rate');
  meter.reset();
  assert.equal(meter.bytesPerSecond(6000), 0);
});
