# fbakit lipsync: forced alignment speaks the transcript with espeak-ng (already installed for
# `speak`); recognition without a transcript runs PocketSphinx with its English model.
apt-get install -y --no-install-recommends espeak-ng pocketsphinx pocketsphinx-en-us
