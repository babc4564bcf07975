// The Falcon's standard-firmware frames: the byte layout libnifalcon documents, round trips at the
// extremes, and a reader that frames a USB byte stream however it is cut, skipping noise.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "devices/falcon/falcon_frames.hpp"

using namespace hs::falcon;

TEST(FalconFrames, ACommandFrameIsTheDocumentedLayout) {
    Command c;
    c.motor = {0x1234, -1, 0};
    c.leds = kRedLed | kGreenLed;
    c.homing = true;
    const Frame f = encodeCommand(c);
    // '<', 0x1234 as nibbles 4 3 2 1, 0xFFFF, 0x0000, LEDs | homing = 0xB, a spare nibble, '>'
    const std::string expected = std::string("<") + "EDCB" + "PPPP" + "AAAA" + "L" + "A" + ">";
    EXPECT_EQ(std::string(f.begin(), f.end()), expected);
    Command back;
    ASSERT_TRUE(decodeCommand(f.data(), back));
    EXPECT_EQ(back.motor, c.motor);
    EXPECT_EQ(back.leds, c.leds);
    EXPECT_TRUE(back.homing);
}

TEST(FalconFrames, StatusFramesRoundTripAtTheExtremes) {
    for (std::int16_t v : {std::int16_t(0), std::int16_t(1), std::int16_t(-1), std::int16_t(32767), std::int16_t(-32768)})
        for (int h : {0, 1, 5, 7})
            for (int b : {0, 3, 15}) {
                const auto homed = static_cast<std::uint8_t>(h), buttons = static_cast<std::uint8_t>(b);
                Status s;
                s.encoder = {v, static_cast<std::int16_t>(-v), 1234};
                s.homed = homed;
                s.buttons = buttons;
                const Frame f = encodeStatus(s);
                Status back;
                ASSERT_TRUE(decodeStatus(f.data(), back));
                EXPECT_EQ(back.encoder, s.encoder);
                EXPECT_EQ(back.homed, homed);
                EXPECT_EQ(back.buttons, buttons);
                EXPECT_EQ(back.allHomed(), homed == 7);
            }
}

TEST(FalconFrames, MalformedFramesAreRefused) {
    Status s;
    s.encoder = {10, 20, 30};
    Frame f = encodeStatus(s);
    Status out;
    for (std::size_t i = 0; i < kFrameSize; ++i) {
        Frame bad = f;
        bad[i] = i == 13 ? 0x20 : static_cast<std::uint8_t>(i == 0 || i == 15 ? 'x' : 0x3F);
        EXPECT_FALSE(decodeStatus(bad.data(), out)) << "byte " << i;
    }
    Command c;
    Frame cmd = encodeCommand(c);
    cmd[5] = 0x51;
    EXPECT_FALSE(decodeCommand(cmd.data(), c));
}

namespace {
std::vector<std::uint8_t> streamOf(int count, std::vector<Status>* sent) {
    std::vector<std::uint8_t> bytes;
    for (int k = 0; k < count; ++k) {
        Status s;
        s.encoder = {static_cast<std::int16_t>(k * 37), static_cast<std::int16_t>(-k), static_cast<std::int16_t>(k * k)};
        s.homed = static_cast<std::uint8_t>(k % 8);
        s.buttons = static_cast<std::uint8_t>(k % 16);
        sent->push_back(s);
        const Frame f = encodeStatus(s);
        bytes.insert(bytes.end(), f.begin(), f.end());
    }
    return bytes;
}
}  // namespace

TEST(FalconFrames, TheReaderFramesAStreamCutAnywhere) {
    std::vector<Status> sent;
    const std::vector<std::uint8_t> bytes = streamOf(40, &sent);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 50; ++trial) {
        FrameReader reader;
        std::vector<Status> got;
        std::size_t at = 0;
        while (at < bytes.size()) {
            const std::size_t n = std::min<std::size_t>(bytes.size() - at, rng() % 40);
            reader.feed(bytes.data() + at, n);
            at += n;
            Status s;
            while (reader.next(s)) got.push_back(s);
        }
        ASSERT_EQ(got.size(), sent.size());
        for (std::size_t k = 0; k < sent.size(); ++k) {
            EXPECT_EQ(got[k].encoder, sent[k].encoder);
            EXPECT_EQ(got[k].buttons, sent[k].buttons);
        }
        EXPECT_EQ(reader.skippedBytes(), 0u);
    }
}

TEST(FalconFrames, NoiseAndCutFramesAreSkippedAndCounted) {
    std::vector<Status> sent;
    std::vector<std::uint8_t> bytes = streamOf(3, &sent);
    // noise before, a frame cut short after 6 bytes, a stray '<' and a '>' between frames
    std::vector<std::uint8_t> noisy = {0x00, 'x', '>'};
    noisy.insert(noisy.end(), bytes.begin(), bytes.begin() + 16);
    noisy.insert(noisy.end(), bytes.begin() + 16, bytes.begin() + 22);
    noisy.push_back('<');
    noisy.insert(noisy.end(), bytes.begin() + 32, bytes.end());
    FrameReader reader;
    EXPECT_EQ(reader.feed(noisy.data(), noisy.size()), 2);
    Status s;
    ASSERT_TRUE(reader.next(s));
    EXPECT_EQ(s.encoder, sent[0].encoder);
    ASSERT_TRUE(reader.next(s));
    EXPECT_EQ(s.encoder, sent[2].encoder);
    EXPECT_FALSE(reader.next(s));
    EXPECT_EQ(reader.skippedBytes(), 3u + 6u + 1u);
}

TEST(FalconFrames, LatestTakesTheNewestAndAFullRingKeepsTheNewest) {
    std::vector<Status> sent;
    const std::vector<std::uint8_t> bytes = streamOf(20, &sent);
    FrameReader reader;
    EXPECT_EQ(reader.feed(bytes.data(), bytes.size()), 20);
    Status s;
    ASSERT_TRUE(reader.next(s));
    EXPECT_EQ(s.encoder, sent[12].encoder);  // (the ring holds 8: the 12 oldest went)
    ASSERT_TRUE(reader.latest(s));
    EXPECT_EQ(s.encoder, sent[19].encoder);
    EXPECT_FALSE(reader.next(s));
    EXPECT_EQ(reader.frames(), 20u);
}
