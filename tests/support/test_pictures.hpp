#pragma once
/// @file test_pictures.hpp
/// The file names of every picture in tests/data/images (SOURCES.md gives each one's source and licence),
/// for tests that run on all of them: ::testing::ValuesIn(test::kPictures).

namespace hk::test {

inline constexpr const char* kPictures[] = {
    "HappyFish.jpg",    "LinuxLogo.jpg",    "apple.jpg",         "butterfly.jpg",    "camera.png",
    "coins.png",        "fruits.jpg",       "horse.png",         "page.png",         "pic1.png",
    "pic3.png",         "silhouette_1.png", "silhouette_10.png", "silhouette_2.png", "silhouette_3.png",
    "silhouette_4.png", "silhouette_5.png", "silhouette_6.png",  "silhouette_7.png", "silhouette_8.png",
    "silhouette_9.png", "sudoku.png",
};

}  // namespace hk::test
