// encoder_bridge.ino: the Arduino side of the pixyslam encoder bridge.
//
// Counts two quadrature wheel encoders with one pin-change interrupt and sends
// a snapshot of both counters with the time and a sequence number at 50 Hz as
// ASCII lines over the USB serial port:
//
//   $RST,<firmware version>,<ticks per revolution>*CS\r\n   once, after boot
//   $ENC,<seq>,<micros>,<left ticks>,<right ticks>*CS\r\n   every 20 ms
//
// CS = XOR of the bytes between '$' and '*', two upper-case hex digits. Full
// specification: docs/arduino_protocol.md. Board: Arduino Uno (ATmega328P,
// 16 MHz). Counters are raw (no direction sign, no wheel geometry): the
// bridge on the Raspberry Pi applies those from its YAML configuration.

#include <Arduino.h>
#include <stdio.h>
#include <util/atomic.h>

// ---- Configuration ---------------------------------------------------------

static const char kFirmwareVersion[] = "1.0.0";
// Counts per wheel revolution with 4x decoding (sent in RST for the bridge to
// cross-check; 0 if unknown). E.g. 11 magnet pulses x 4 edges x 30:1 gearbox.
static const unsigned long kTicksPerRevolution = 1320UL;
static const unsigned long kSamplePeriodUs = 20000UL;  // 50 Hz
static const unsigned long kBaud = 115200UL;

// Both encoders on port D (D0..D7), so one pin-change interrupt, PCINT2, sees
// all four channels. D0/D1 are the serial port and stay out of the mask.
static const uint8_t kLeftAPin = 2;   // PD2, PCINT18
static const uint8_t kLeftBPin = 3;   // PD3, PCINT19
static const uint8_t kRightAPin = 4;  // PD4, PCINT20
static const uint8_t kRightBPin = 5;  // PD5, PCINT21
static const uint8_t kLeftShift = 2;  // left (B << 1 | A) = (PIND >> 2) & 3
static const uint8_t kRightShift = 4;  // right (B << 1 | A) = (PIND >> 4) & 3

// ---- Quadrature decoding -----------------------------------------------------

// Step for a transition, indexed by (previous state << 2) | new state, where
// state = (B << 1) | A. Forward (A leads B) runs 00 -> 01 -> 11 -> 10 -> 00 in
// (B A) order and counts +1 per edge; backwards counts -1. No change, or both
// channels changed at once (an edge was missed), counts 0.
static const int8_t kQuadratureStep[16] = {
    0,  +1, -1, 0,   // from 00
    -1, 0,  0,  +1,  // from 01
    +1, 0,  0,  -1,  // from 10
    0,  -1, +1, 0,   // from 11
};

// Cumulative counts. Unsigned so that wrap-around at 2^32 is well defined; sent
// as the int32 with the same bits. Written only by the ISR; read with
// interrupts off (a 32-bit read takes several instructions on an 8-bit AVR).
static volatile uint32_t g_left_count = 0;
static volatile uint32_t g_right_count = 0;
// Last decoded channel states; used only by the ISR once it is enabled.
static uint8_t g_left_state = 0;
static uint8_t g_right_state = 0;

ISR(PCINT2_vect) {
  const uint8_t pins = PIND;  // one read: both encoders at the same instant
  const uint8_t left = (pins >> kLeftShift) & 0x03;
  const uint8_t right = (pins >> kRightShift) & 0x03;
  g_left_count += (uint32_t)(int32_t)kQuadratureStep[(g_left_state << 2) | left];
  g_right_count += (uint32_t)(int32_t)kQuadratureStep[(g_right_state << 2) | right];
  g_left_state = left;
  g_right_state = right;
}

// ---- Line output -----------------------------------------------------------

static uint32_t g_seq = 0;
static uint32_t g_next_sample_us = 0;

// Writes "$<body>*CS\r\n" in one call. Returns false, writing nothing, if the
// transmit buffer cannot take the whole line (never blocks the sample loop).
static bool send_line(const char* body, bool may_drop) {
  static const char kHex[] = "0123456789ABCDEF";
  char line[64];
  uint8_t checksum = 0;
  size_t n = 0;
  line[n++] = '$';
  for (const char* p = body; *p != '\0' && n < sizeof(line) - 5; ++p) {
    checksum ^= (uint8_t)*p;
    line[n++] = *p;
  }
  line[n++] = '*';
  line[n++] = kHex[checksum >> 4];
  line[n++] = kHex[checksum & 0x0F];
  line[n++] = '\r';
  line[n++] = '\n';
  if (may_drop && (size_t)Serial.availableForWrite() < n) return false;
  Serial.write((const uint8_t*)line, n);
  return true;
}

static void send_reset_line() {
  char body[40];
  snprintf(body, sizeof(body), "RST,%s,%lu", kFirmwareVersion, kTicksPerRevolution);
  send_line(body, false);  // once at boot: wait for room rather than lose it
}

static void send_sample() {
  uint32_t time_us;
  uint32_t left;
  uint32_t right;
  ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
    time_us = micros();  // safe with interrupts off: it checks the pending timer-0 overflow
    left = g_left_count;
    right = g_right_count;
  }
  // "ENC," + 2 x 10 digits + 2 x 11 characters + 4 commas = 49 characters at most.
  char body[56];
  snprintf(body, sizeof(body), "ENC,%lu,%lu,%ld,%ld", (unsigned long)g_seq, (unsigned long)time_us,
           (long)(int32_t)left, (long)(int32_t)right);
  send_line(body, true);  // a dropped line shows on the Pi as a gap in seq
  ++g_seq;
}

// ---- Arduino entry points --------------------------------------------------

void setup() {
  // Hall and optical encoder boards often have open-collector outputs.
  pinMode(kLeftAPin, INPUT_PULLUP);
  pinMode(kLeftBPin, INPUT_PULLUP);
  pinMode(kRightAPin, INPUT_PULLUP);
  pinMode(kRightBPin, INPUT_PULLUP);

  Serial.begin(kBaud);

  const uint8_t pins = PIND;
  g_left_state = (pins >> kLeftShift) & 0x03;
  g_right_state = (pins >> kRightShift) & 0x03;
  PCMSK2 |= bit(PCINT18) | bit(PCINT19) | bit(PCINT20) | bit(PCINT21);
  PCIFR = bit(PCIF2);   // clear a change that happened during set-up (write 1 to clear)
  PCICR |= bit(PCIE2);  // enable pin-change interrupts on port D

  send_reset_line();
  g_next_sample_us = micros();
}

void loop() {
  const uint32_t now = micros();
  // Signed difference: right across the micros() wrap every ~71.6 min.
  if ((int32_t)(now - g_next_sample_us) < 0) return;
  g_next_sample_us += kSamplePeriodUs;
  if ((int32_t)(now - g_next_sample_us) >= 0) {
    // More than a whole period late (e.g. the port was blocked): skip the
    // missed slots instead of sending a burst.
    g_next_sample_us = now + kSamplePeriodUs;
  }
  send_sample();
}
